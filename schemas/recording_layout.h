#pragma once
// Paths and attribute names of a recording file (HDF5), version 1.
// The human-readable spec is session_format.md; keep the two in step and bump
// kRecordingSchemaVersion on any change a v1 reader could misread.
#include <array>
#include <string_view>

namespace speckle::layout {

inline constexpr std::string_view kRecordingSchemaName = "speckle.recording";
inline constexpr int kRecordingSchemaVersion = 1;

// Root attributes.
inline constexpr const char* kAttrSchema = "schema";
inline constexpr const char* kAttrSchemaVersion = "schema_version";
inline constexpr const char* kAttrPurpose = "purpose";
inline constexpr const char* kAttrSource = "source";
inline constexpr const char* kAttrSourcePath = "source_path";
inline constexpr const char* kAttrToolVersion = "tool_version";
inline constexpr const char* kAttrCreatedUtc = "created_utc";

// One group per image stream; the same members in each.
inline constexpr const char* kColour = "colour";
inline constexpr const char* kDepth = "depth";
inline constexpr const char* kIr = "ir";
inline constexpr std::array<const char*, 3> kStreams = {kColour, kDepth, kIr};
inline constexpr const char* kFrames = "frames";                     // N×H×W(×3)
inline constexpr const char* kValid = "valid";                       // uint8 [N]
inline constexpr const char* kDeviceTimestamp = "device_timestamp";  // uint64 [N]
inline constexpr const char* kHostTimeNs = "host_time_ns";           // int64 [N]
// Attributes of depth/frames.
inline constexpr const char* kAttrUnits = "units";
inline constexpr const char* kAttrInvalidValue = "invalid_value";

// Source frame number of each pair (file number in a frame folder), -1 = none.
inline constexpr const char* kSourceNumber = "source_number";

// Accelerometer samples (libfreenect tilt state), optional.
inline constexpr const char* kAccel = "accel";
inline constexpr const char* kAccelCounts = "counts";           // int16 [M,3]
inline constexpr const char* kAccelTiltAngle = "tilt_angle";    // int8 [M]
inline constexpr const char* kAccelTiltStatus = "tilt_status";  // int8 [M]

// Device registration constants (libfreenect device.json), optional.
inline constexpr const char* kDevice = "device";
inline constexpr const char* kAttrRegistrationJson = "registration_json";

// Simulator ground truth. Only evaluation code may read it.
inline constexpr const char* kTruth = "truth";
inline constexpr const char* kAttrScenarioJson = "scenario_json";

}  // namespace speckle::layout
