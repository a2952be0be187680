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
  if (!IsHdf5(path)) throw InputError(where + ": not an HDF5 file (expected a speckle recording)");
  try {
    impl_->file = H5::H5File(where, H5F_ACC_RDONLY);
  } catch (const H5::Exception&) {
    // A writer that died leaves the SWMR "open for writing" mark; SWMR read
    // access is made for exactly that file state.
    try {
      impl_->file = H5::H5File(where, H5F_ACC_RDONLY | H5F_ACC_SWMR_READ);
      closed_cleanly_ = false;
    } catch (const H5::Exception& e) {
      // HDF5 says only that the open failed; a file cut short (copied or
      // downloaded in part) is the usual cause, so its size is given.
      throw InputError(where + ": cannot open HDF5 file (" + e.getDetailMsg() + "): damaged or cut short, " +
                       std::to_string(std::filesystem::file_size(path)) + " bytes");
    }
  }
  H5::H5File& file = impl_->file;
  try {
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
      header_.purpose = PurposeFromString(h5::ReadStringAttribute(file, layout::kAttrPurpose, where));
    } catch (const SchemaVersionError&) {
      throw;
    } catch (const InputError& e) {
      throw InputError(where + ": attribute 'purpose': " + e.what());
    }
    header_.source = h5::ReadStringAttribute(file, layout::kAttrSource, where);
    header_.source_path = h5::ReadStringAttribute(file, layout::kAttrSourcePath, where);
    // Required by the format, though nothing here needs their values.
    h5::ReadStringAttribute(file, layout::kAttrToolVersion, where);
    h5::ReadStringAttribute(file, layout::kAttrCreatedUtc, where);

    std::vector<std::pair<std::string, hsize_t>> lengths;
    const auto note_length = [&](const std::string& name, const H5::DataSet& d) {
      lengths.emplace_back(name, h5::Dimensions(d)[0]);
    };
    for (int i = 0; i < 3; ++i) {
      const char* name = layout::kStreams[i];
      if (!h5::Exists(file, name)) continue;
      impl_->streams[i] = file.openGroup(name);
      for (const char* member : {layout::kFrames, layout::kValid, layout::kDeviceTimestamp, layout::kHostTimeNs}) {
        if (!h5::Exists(*impl_->streams[i], member)) {
          throw InputError(where + ": missing dataset /" + name + "/" + member);
        }
        note_length(std::string("/") + name + "/" + member, impl_->streams[i]->openDataSet(member));
      }
      impl_->frames[i] = impl_->streams[i]->openDataSet(layout::kFrames);
      const auto dims = h5::Dimensions(*impl_->frames[i]);
      const bool colour = i == 0;
      const auto type_class = impl_->frames[i]->getTypeClass();
      const std::size_t type_size = impl_->frames[i]->getDataType().getSize();
      if (dims.size() != (colour ? 4u : 3u) || (colour && dims[3] != 3) || type_class != H5T_INTEGER ||
          type_size != (colour ? 1u : 2u)) {
        throw InputError(where + ": dataset /" + name + "/frames should be " +
                         (colour ? "uint8 N x H x W x 3" : "uint16 N x H x W"));
      }
      const cv::Size size(static_cast<int>(dims[2]), static_cast<int>(dims[1]));
      (i == 0 ? header_.colour_size : i == 1 ? header_.depth_size : header_.ir_size) = size;
    }
    if (!header_.depth_size && !header_.colour_size && !header_.ir_size) {
      throw InputError(where + ": holds no /colour, /depth or /ir frames");
    }
    if (impl_->frames[1]) {
      const std::string units_where = where + ": /depth/frames";
      try {
        header_.depth_units =
            DepthUnitsFromString(h5::ReadStringAttribute(*impl_->frames[1], layout::kAttrUnits, units_where));
      } catch (const SchemaVersionError&) {
        throw;
      } catch (const InputError& e) {
        throw InputError(units_where + ": attribute 'units': " + e.what());
      }
    }
    if (!h5::Exists(file, layout::kSourceNumber)) throw InputError(where + ": missing dataset /source_number");
    note_length("/source_number", file.openDataSet(layout::kSourceNumber));
    header_.has_accel = h5::Exists(file, layout::kAccel);
    if (h5::Exists(file, layout::kDevice)) {
      header_.device_registration_json =
          h5::ReadStringAttribute(file.openGroup(layout::kDevice), layout::kAttrRegistrationJson, where + ": /device");
    }
    if (h5::Exists(file, layout::kTruth)) {
      header_.scenario_json =
          h5::ReadStringAttribute(file.openGroup(layout::kTruth), layout::kAttrScenarioJson, where + ": /truth");
    }

    const auto [shortest, longest] = std::minmax_element(
        lengths.begin(), lengths.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    frame_count_ = static_cast<std::int64_t>(shortest->second);
    if (shortest->second != longest->second) {
      if (closed_cleanly_) {
        throw InputError(where + ": dataset " + longest->first + " holds " + std::to_string(longest->second) +
                         " entries but " + shortest->first + " holds " + std::to_string(shortest->second) +
                         "; a cleanly closed recording has one entry per frame in each");
      }
      truncation_note_ =
          "the recorder stopped mid-frame; using the " + std::to_string(frame_count_) + " frames every dataset holds";
    }
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
