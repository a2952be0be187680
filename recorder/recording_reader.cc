#include "recorder/recording_reader.h"

#include <algorithm>
#include <fstream>

#include "schemas/errors.h"
#include "schemas/h5_access.h"
#include "schemas/recording_layout.h"

namespace speckle {
namespace {

template <typename T>
std::vector<T> ReadAll(const H5::DataSet& dataset, const H5::PredType& type, hsize_t count, hsize_t per_entry = 1) {
  std::vector<T> values(count * per_entry);
  if (count == 0) return values;
  // A damaged or hand-made file can hold strings, another shape or too few
  // entries here: name the dataset instead of letting H5::Exception escape.
  const auto where = [&] { return dataset.getFileName() + ": " + dataset.getObjName(); };
  const H5T_class_t kind = dataset.getTypeClass();
  if (kind != H5T_INTEGER && kind != H5T_FLOAT) throw InputError(where() + ": expected numbers, found another type");
  std::vector<hsize_t> dims = h5::Dimensions(dataset), offset(dims.size(), 0);
  hsize_t per = 1;
  for (std::size_t d = 1; d < dims.size(); ++d) per *= dims[d];
  if (dims.empty() || dims[0] < count || per != per_entry)
    throw InputError(where() + ": expected " + std::to_string(count) + " entries of " + std::to_string(per_entry) +
                     " values, found another shape");
  try {
    H5::DataSpace file_space = dataset.getSpace();
    dims[0] = count;
    file_space.selectHyperslab(H5S_SELECT_SET, dims.data(), offset.data());
    const H5::DataSpace memory_space(static_cast<int>(dims.size()), dims.data());
    dataset.read(values.data(), type, memory_space, file_space);
  } catch (const H5::Exception& e) {
    throw InputError(where() + ": cannot be read (" + e.getDetailMsg() + ")");
  }
  return values;
}

bool IsHdf5(const std::filesystem::path& path) {
  static constexpr char kSignature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  in.read(head, 8);
  return in.gcount() == 8 && std::equal(head, head + 8, kSignature);
}

// A writer that died leaves the SWMR "open for writing" mark; SWMR read
// access is made for exactly that file state, and *closed_cleanly says so.
H5::H5File OpenRecordingFile(const std::filesystem::path& path, bool* closed_cleanly) {
  const std::string where = path.string();
  try {
    return H5::H5File(where, H5F_ACC_RDONLY);
  } catch (const H5::Exception&) {
    try {
      // SWMR retries a metadata read whose checksum fails, expecting a live
      // writer to finish it: 100 times with a growing sleep by default, so
      // one damaged superblock byte held every tool for over 10 minutes. A
      // dead writer's file no longer changes; a failed checksum is damage.
      H5::FileAccPropList access;
      H5Pset_metadata_read_attempts(access.getId(), 1);
      H5::H5File file(where, H5F_ACC_RDONLY | H5F_ACC_SWMR_READ, H5::FileCreatPropList::DEFAULT, access);
      *closed_cleanly = false;
      return file;
    } catch (const H5::Exception& e) {
      // HDF5 says only that the open failed; a file cut short (copied or
      // downloaded in part) is the usual cause, so its size is given.
      throw InputError(where + ": cannot open HDF5 file (" + e.getDetailMsg() + "): damaged or cut short, " +
                       std::to_string(std::filesystem::file_size(path)) + " bytes");
    }
  }
}

void ReadRootAttributes(const H5::H5File& file, const std::string& where, RecordingHeader& header) {
  const std::string schema = h5::ReadStringAttribute(file, layout::kAttrSchema, where);
  if (schema != layout::kRecordingSchemaName) {
    throw InputError(where + ": attribute 'schema' is \"" + schema + "\", expected \"" +
                     std::string(layout::kRecordingSchemaName) + "\"");
  }
  const long long version = h5::ReadIntAttribute(file, layout::kAttrSchemaVersion, where);
  if (version != layout::kRecordingSchemaVersion) {
    throw SchemaVersionError(where + ": recording schema version " + std::to_string(version) +
                             " is not understood by this tool (it reads version " +
                             std::to_string(layout::kRecordingSchemaVersion) + ")");
  }
  try {
    header.purpose = PurposeFromString(h5::ReadStringAttribute(file, layout::kAttrPurpose, where));
  } catch (const SchemaVersionError&) {
    throw;
  } catch (const InputError& e) {
    throw InputError(where + ": attribute 'purpose': " + e.what());
  }
  header.source = h5::ReadStringAttribute(file, layout::kAttrSource, where);
  header.source_path = h5::ReadStringAttribute(file, layout::kAttrSourcePath, where);
  // Required by the format, though nothing here needs their values.
  h5::ReadStringAttribute(file, layout::kAttrToolVersion, where);
  h5::ReadStringAttribute(file, layout::kAttrCreatedUtc, where);
}

constexpr hsize_t kMaxFrameSide = 4096;

// Each dataset's name and length: they must agree, but in a file a killed
// writer left (FrameCountOfAll).
using DatasetLengths = std::vector<std::pair<std::string, hsize_t>>;

// The frames of stream `stream` (0 colour, 1 depth, 2 ir) in its group, with
// the group's four datasets there (their lengths noted) and the frames of the
// stream's type and shape.
H5::DataSet OpenStreamFrames(const H5::Group& group, int stream, const std::string& where, DatasetLengths& lengths) {
  const char* name = layout::kStreams[stream];
  for (const char* member : {layout::kFrames, layout::kValid, layout::kDeviceTimestamp, layout::kHostTimeNs}) {
    if (!h5::Exists(group, member)) throw InputError(where + ": missing dataset /" + name + "/" + member);
    lengths.emplace_back(std::string("/") + name + "/" + member, h5::Dimensions(group.openDataSet(member))[0]);
  }
  H5::DataSet frames = group.openDataSet(layout::kFrames);
  const auto dims = h5::Dimensions(frames);
  const bool colour = stream == 0;
  const auto type_class = frames.getTypeClass();
  const std::size_t type_size = frames.getDataType().getSize();
  if (dims.size() != (colour ? 4u : 3u) || (colour && dims[3] != 3) || type_class != H5T_INTEGER ||
      type_size != (colour ? 1u : 2u)) {
    throw InputError(where + ": dataset /" + name + "/frames should be " +
                     (colour ? "uint8 N x H x W x 3" : "uint16 N x H x W"));
  }
  // A frame is read whole: a shape claiming more than any Kinect stream (colour at most 1280 x 1024) would
  // allocate gigabytes for one frame before a byte is checked.
  if (dims[1] == 0 || dims[2] == 0 || dims[1] > kMaxFrameSide || dims[2] > kMaxFrameSide)
    throw InputError(where + ": dataset /" + name + "/frames claims " + std::to_string(dims[2]) + " x " +
                     std::to_string(dims[1]) + " pixel frames; a recording's are 1 to " +
                     std::to_string(kMaxFrameSide) + " on each side");
  return frames;
}

DepthUnits ReadDepthUnits(const H5::DataSet& depth_frames, const std::string& where) {
  const std::string units_where = where + ": /depth/frames";
  try {
    return DepthUnitsFromString(h5::ReadStringAttribute(depth_frames, layout::kAttrUnits, units_where));
  } catch (const SchemaVersionError&) {
    throw;
  } catch (const InputError& e) {
    throw InputError(units_where + ": attribute 'units': " + e.what());
  }
}

// What the recording holds beside its streams: the source numbers (a length
// to agree with the streams'), accelerometer, device registration, truth.
void ReadSessionExtras(const H5::H5File& file, const std::string& where, RecordingHeader& header,
                       DatasetLengths& lengths) {
  if (!h5::Exists(file, layout::kSourceNumber)) throw InputError(where + ": missing dataset /source_number");
  lengths.emplace_back("/source_number", h5::Dimensions(file.openDataSet(layout::kSourceNumber))[0]);
  header.has_accel = h5::Exists(file, layout::kAccel);
  if (h5::Exists(file, layout::kDevice)) {
    header.device_registration_json =
        h5::ReadStringAttribute(file.openGroup(layout::kDevice), layout::kAttrRegistrationJson, where + ": /device");
  }
  if (h5::Exists(file, layout::kTruth)) {
    header.scenario_json =
        h5::ReadStringAttribute(file.openGroup(layout::kTruth), layout::kAttrScenarioJson, where + ": /truth");
  }
}

// The frames every dataset holds. A cleanly closed file has one entry per
// frame in each; a killed writer's may stop mid-frame, and the note says so.
std::int64_t FrameCountOfAll(const DatasetLengths& lengths, bool closed_cleanly, const std::string& where,
                             std::string* truncation_note) {
  const auto [shortest, longest] = std::minmax_element(
      lengths.begin(), lengths.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  const auto frames = static_cast<std::int64_t>(shortest->second);
  if (shortest->second != longest->second) {
    // One frame short in some datasets is the frame a failed write (a full
    // disk) left half-written; the writer still closes the file, so its flag
    // says closed. More than one is damage.
    if (closed_cleanly && longest->second - shortest->second > 1) {
      throw InputError(where + ": dataset " + longest->first + " holds " + std::to_string(longest->second) +
                       " entries but " + shortest->first + " holds " + std::to_string(shortest->second) +
                       "; a cleanly closed recording has one entry per frame in each");
    }
    *truncation_note = "the recorder stopped mid-frame (killed, or a write failed); using the " +
                       std::to_string(frames) + " frames every dataset holds";
  }
  return frames;
}

}  // namespace

struct RecordingReader::Impl {
  H5::H5File file;
  std::array<std::optional<H5::Group>, 3> streams;
  std::array<std::optional<H5::DataSet>, 3> frames;
};

RecordingReader::RecordingReader(const std::filesystem::path& path) : path_(path), impl_(std::make_unique<Impl>()) {
  h5::SilenceLibraryErrors();
  const std::string where = path.string();
  if (!std::filesystem::exists(path)) throw InputError(where + ": no such recording file");
  if (std::filesystem::is_directory(path)) throw InputError(where + ": a folder, not a recording file");
  if (!IsHdf5(path)) throw InputError(where + ": not an HDF5 file (expected a speckle recording)");
  impl_->file = OpenRecordingFile(path, &closed_cleanly_);
  H5::H5File& file = impl_->file;
  try {
    ReadRootAttributes(file, where, header_);
    DatasetLengths lengths;
    for (int i = 0; i < 3; ++i) {
      if (!h5::Exists(file, layout::kStreams[i])) continue;
      impl_->streams[i] = file.openGroup(layout::kStreams[i]);
      impl_->frames[i] = OpenStreamFrames(*impl_->streams[i], i, where, lengths);
      const auto dims = h5::Dimensions(*impl_->frames[i]);
      const cv::Size size(static_cast<int>(dims[2]), static_cast<int>(dims[1]));
      (i == 0 ? header_.colour_size : i == 1 ? header_.depth_size : header_.ir_size) = size;
    }
    if (!header_.depth_size && !header_.colour_size && !header_.ir_size) {
      throw InputError(where + ": holds no /colour, /depth or /ir frames");
    }
    if (impl_->frames[1]) header_.depth_units = ReadDepthUnits(*impl_->frames[1], where);
    ReadSessionExtras(file, where, header_, lengths);
    frame_count_ = FrameCountOfAll(lengths, closed_cleanly_, where, &truncation_note_);
  } catch (const H5::Exception& e) {
    throw InputError(where + ": unreadable recording: " + e.getDetailMsg());
  }
}

RecordingReader::~RecordingReader() = default;

// An 11-bit sensor gives 0 to 2047 (no reading; some dumps' PGM maxval is
// 2048): a larger value is a damaged chunk (szip decodes garbage without
// complaint), not a depth.
void RecordingReader::RefuseRawAbove11Bits(const cv::Mat& raw, std::int64_t index) const {
  double highest = 0;
  cv::minMaxLoc(raw, nullptr, &highest);
  if (highest > 2048) {
    throw InputError(path_.string() + ": frame " + std::to_string(index) + ": depth value " +
                     std::to_string(static_cast<int>(highest)) +
                     " above 2048 in an 11-bit recording (a damaged chunk?)");
  }
}

FramePair RecordingReader::ReadFrame(std::int64_t index, unsigned streams) const {
  h5::SilenceLibraryErrors();  // on this thread: frames are read on the graph's workers
  if (index < 0 || index >= frame_count_) {
    throw std::out_of_range(path_.string() + ": frame " + std::to_string(index) + " out of range [0, " +
                            std::to_string(frame_count_) + ")");
  }
  FramePair pair;
  StreamFrame* targets[3] = {&pair.colour, &pair.depth, &pair.ir};
  try {
    for (int i = 0; i < 3; ++i) {
      if (!impl_->frames[i]) continue;
      const H5::Group& group = *impl_->streams[i];
      const auto read_one = [&](const char* name, const H5::PredType& type, void* out) {
        const H5::DataSet d = group.openDataSet(name);
        H5::DataSpace space = d.getSpace();
        const hsize_t offset = static_cast<hsize_t>(index), count = 1;
        space.selectHyperslab(H5S_SELECT_SET, &count, &offset);
        d.read(out, type, H5::DataSpace(1, &count), space);
      };
      std::uint8_t valid = 0;
      read_one(layout::kValid, H5::PredType::NATIVE_UINT8, &valid);
      read_one(layout::kDeviceTimestamp, H5::PredType::NATIVE_UINT64, &targets[i]->device_timestamp);
      read_one(layout::kHostTimeNs, H5::PredType::NATIVE_INT64, &targets[i]->host_time_ns);
      if (!valid || !(streams & (1u << i))) continue;
      std::vector<hsize_t> dims = h5::Dimensions(*impl_->frames[i]), offset(dims.size(), 0);
      dims[0] = 1;
      offset[0] = static_cast<hsize_t>(index);
      const bool colour = i == 0;
      cv::Mat image(static_cast<int>(dims[1]), static_cast<int>(dims[2]), colour ? CV_8UC3 : CV_16UC1);
      H5::DataSpace space = impl_->frames[i]->getSpace();
      space.selectHyperslab(H5S_SELECT_SET, dims.data(), offset.data());
      impl_->frames[i]->read(image.data, colour ? H5::PredType::NATIVE_UINT8 : H5::PredType::NATIVE_UINT16,
                             H5::DataSpace(static_cast<int>(dims.size()), dims.data()), space);
      if (i == 1 && header_.depth_units == DepthUnits::kRaw11Bit) RefuseRawAbove11Bits(image, index);
      targets[i]->image = image;
    }
    const H5::DataSet numbers = impl_->file.openDataSet(layout::kSourceNumber);
    H5::DataSpace space = numbers.getSpace();
    const hsize_t offset = static_cast<hsize_t>(index), count = 1;
    space.selectHyperslab(H5S_SELECT_SET, &count, &offset);
    numbers.read(&pair.source_number, H5::PredType::NATIVE_INT64, H5::DataSpace(1, &count), space);
  } catch (const H5::Exception& e) {
    throw InputError(path_.string() + ": frame " + std::to_string(index) + " unreadable: " + e.getDetailMsg());
  }
  return pair;
}

RecordingReader::StreamClock RecordingReader::ReadClock(int stream) const {
  StreamClock clock;
  if (!impl_->streams[stream]) return clock;
  const H5::Group& g = *impl_->streams[stream];
  const auto n = static_cast<hsize_t>(frame_count_);
  clock.valid = ReadAll<std::uint8_t>(g.openDataSet(layout::kValid), H5::PredType::NATIVE_UINT8, n);
  clock.device_timestamp =
      ReadAll<std::uint64_t>(g.openDataSet(layout::kDeviceTimestamp), H5::PredType::NATIVE_UINT64, n);
  clock.host_time_ns = ReadAll<std::int64_t>(g.openDataSet(layout::kHostTimeNs), H5::PredType::NATIVE_INT64, n);
  return clock;
}

std::vector<AccelSample> RecordingReader::ReadAccel() const {
  std::vector<AccelSample> samples;
  if (!header_.has_accel) return samples;
  const std::string where = path_.string() + ": /accel";
  try {
    const H5::Group g = impl_->file.openGroup(layout::kAccel);
    hsize_t n = h5::Dimensions(g.openDataSet(layout::kHostTimeNs))[0];
    for (const char* name :
         {layout::kDeviceTimestamp, layout::kAccelCounts, layout::kAccelTiltAngle, layout::kAccelTiltStatus}) {
      n = std::min(n, h5::Dimensions(g.openDataSet(name))[0]);
    }
    const auto host = ReadAll<std::int64_t>(g.openDataSet(layout::kHostTimeNs), H5::PredType::NATIVE_INT64, n);
    const auto device = ReadAll<std::uint64_t>(g.openDataSet(layout::kDeviceTimestamp), H5::PredType::NATIVE_UINT64, n);
    const auto counts = ReadAll<std::int16_t>(g.openDataSet(layout::kAccelCounts), H5::PredType::NATIVE_INT16, n, 3);
    const auto angle = ReadAll<std::int8_t>(g.openDataSet(layout::kAccelTiltAngle), H5::PredType::NATIVE_INT8, n);
    const auto status = ReadAll<std::int8_t>(g.openDataSet(layout::kAccelTiltStatus), H5::PredType::NATIVE_INT8, n);
    for (hsize_t k = 0; k < n; ++k) {
      samples.push_back(
          {host[k], device[k], {counts[3 * k], counts[3 * k + 1], counts[3 * k + 2]}, angle[k], status[k]});
    }
  } catch (const H5::Exception& e) {
    throw InputError(where + ": unreadable: " + e.getDetailMsg());
  }
  return samples;
}

}  // namespace speckle
