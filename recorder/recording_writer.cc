#include "recorder/recording_writer.h"

#include <tbb/parallel_invoke.h>

#include "schemas/atomic_file.h"
#include "schemas/errors.h"
#include "schemas/h5_access.h"
#include "schemas/recording_layout.h"
#include "speckle/tool_version.h"

namespace speckle {
namespace {

constexpr hsize_t kSeriesChunkFrames = 256;

// A dataset that grows by one entry per frame along its first dimension.
// Entries wait in memory until the next flush and are then written in one
// call: they only become durable at a flush anyway, and one write per flush
// instead of one per frame keeps the serial write stage short.
struct GrowingDataset {
  H5::DataSet dataset;
  H5::PredType memory_type = H5::PredType::NATIVE_UINT8;
  std::vector<hsize_t> entry_shape;  // shape of one entry, without the frame axis
  std::size_t entry_bytes = 0;
  hsize_t written = 0;
  std::vector<std::uint8_t> pending;

  void AppendEntry(const void* value) {
    const auto* bytes = static_cast<const std::uint8_t*>(value);
    pending.insert(pending.end(), bytes, bytes + entry_bytes);
  }
  void WritePending() {
    if (pending.empty()) return;
    const hsize_t count = pending.size() / entry_bytes;
    std::vector<hsize_t> dims{written + count};
    dims.insert(dims.end(), entry_shape.begin(), entry_shape.end());
    dataset.extend(dims.data());
    H5::DataSpace file_space = dataset.getSpace();
    std::vector<hsize_t> offset(dims.size(), 0), block = dims;
    offset[0] = written;
    block[0] = count;
    file_space.selectHyperslab(H5S_SELECT_SET, block.data(), offset.data());
    const H5::DataSpace memory_space(static_cast<int>(block.size()), block.data());
    dataset.write(pending.data(), memory_type, memory_space, file_space);
    written += count;
    pending.clear();
  }
};

GrowingDataset CreateGrowing(const H5::Group& group, const std::string& name, const H5::PredType& file_type,
                             const H5::PredType& memory_type, std::vector<hsize_t> entry_shape, hsize_t chunk_frames) {
  std::vector<hsize_t> dims{0}, max_dims{H5S_UNLIMITED}, chunk{chunk_frames};
  for (hsize_t d : entry_shape) {
    dims.push_back(d);
    max_dims.push_back(d);
    chunk.push_back(d);
  }
  H5::DSetCreatPropList plist;
  plist.setChunk(static_cast<int>(chunk.size()), chunk.data());
  const H5::DataSpace space(static_cast<int>(dims.size()), dims.data(), max_dims.data());
  std::size_t entry_bytes = memory_type.getSize();
  for (hsize_t d : entry_shape) entry_bytes *= d;
  return {group.createDataSet(name, file_type, space, plist), memory_type, std::move(entry_shape), entry_bytes};
}

// An image stream: frames (one compressed chunk each) plus per-frame clocks.
struct StreamDatasets {
  H5::Group group;
  H5::DataSet frames;
  ChunkCodec codec;
  std::vector<hsize_t> frame_dims;  // current extent of `frames`
  cv::Size size;
  int cv_type = CV_16UC1;
  GrowingDataset valid, device_timestamp, host_time_ns;
};

StreamDatasets CreateStream(H5::H5File& file, const char* name, cv::Size size, bool colour,
                            const RecordingWriterOptions& options, std::optional<int> fill_value) {
  StreamDatasets s;
  s.group = file.createGroup(name);
  s.size = size;
  s.cv_type = colour ? CV_8UC3 : CV_16UC1;
  std::vector<hsize_t> dims{0, hsize_t(size.height), hsize_t(size.width)};
  if (colour) dims.push_back(3);
  std::vector<hsize_t> max_dims = dims, chunk = dims;
  max_dims[0] = H5S_UNLIMITED;
  chunk[0] = 1;
  H5::DSetCreatPropList plist;
  plist.setChunk(static_cast<int>(chunk.size()), chunk.data());
  ChunkCodec::AddFilters(plist.getId(), options.codec, options.deflate_level);
  const H5::PredType& file_type = colour ? H5::PredType::STD_U8LE : H5::PredType::STD_U16LE;
  if (fill_value) {
    const auto fill = static_cast<std::uint16_t>(*fill_value);
    plist.setFillValue(H5::PredType::NATIVE_UINT16, &fill);
  }
  const H5::DataSpace space(static_cast<int>(dims.size()), dims.data(), max_dims.data());
  s.frames = s.group.createDataSet(layout::kFrames, file_type, space, plist);
  s.frame_dims = dims;
  s.codec = ChunkCodec::ForDataset(s.frames.getId(), options.codec, options.deflate_level);
  using P = H5::PredType;
  s.valid = CreateGrowing(s.group, layout::kValid, P::STD_U8LE, P::NATIVE_UINT8, {}, kSeriesChunkFrames);
  s.device_timestamp =
      CreateGrowing(s.group, layout::kDeviceTimestamp, P::STD_U64LE, P::NATIVE_UINT64, {}, kSeriesChunkFrames);
  s.host_time_ns = CreateGrowing(s.group, layout::kHostTimeNs, P::STD_I64LE, P::NATIVE_INT64, {}, kSeriesChunkFrames);
  return s;
}

}  // namespace

struct RecordingWriter::Impl {
  std::unique_ptr<H5::H5File> file;  // held by pointer: a file whose close failed is abandoned, never destroyed
  RecordingHeader header;
  RecordingWriterOptions options;
  std::array<std::optional<StreamDatasets>, 3> streams;  // colour, depth, ir
  GrowingDataset source_number;
  struct Accel {
    GrowingDataset host_time_ns, device_timestamp, counts, tilt_angle, tilt_status;
  };
  std::optional<Accel> accel;
  std::vector<std::pair<PerFrameSeries, GrowingDataset>> series;
  std::chrono::steady_clock::time_point last_flush = std::chrono::steady_clock::now();
  bool closed = false;

  void CloseDatasets();
  // Every object closed once; the close's error when it failed (the file is
  // then abandoned).
  std::optional<std::string> CloseAll();
};

RecordingWriter::RecordingWriter(const std::filesystem::path& path, const RecordingHeader& header,
                                 const RecordingWriterOptions& options)
    : path_(path), impl_(std::make_unique<Impl>()) {
  h5::SilenceLibraryErrors();
  if (!header.depth_size && !header.colour_size && !header.ir_size) {
    throw std::logic_error("a recording needs at least one image stream");
  }
  if (std::filesystem::exists(path)) throw InputError(path.string() + ": already exists; refusing to overwrite");
  impl_->header = header;
  impl_->options = options;
  H5::FileAccPropList access;
  access.setLibverBounds(H5F_LIBVER_LATEST, H5F_LIBVER_LATEST);  // SWMR needs the latest format
  try {
    impl_->file = std::make_unique<H5::H5File>(path.string(), H5F_ACC_EXCL, H5::FileCreatPropList::DEFAULT, access);
  } catch (const H5::Exception& e) {
    throw InputError(path.string() + ": cannot create recording: " + e.getDetailMsg());
  }
  try {
    CreateLayout();
  } catch (...) {
    impl_->closed = true;
    impl_->CloseAll();
    throw;
  }
}

void RecordingWriter::CreateLayout() {
  const RecordingHeader& header = impl_->header;
  const RecordingWriterOptions& options = impl_->options;
  try {
    H5::H5File& file = *impl_->file;
    h5::WriteStringAttribute(file, layout::kAttrSchema, std::string(layout::kRecordingSchemaName));
    h5::WriteIntAttribute(file, layout::kAttrSchemaVersion, layout::kRecordingSchemaVersion);
    h5::WriteStringAttribute(file, layout::kAttrPurpose, ToString(header.purpose));
    h5::WriteStringAttribute(file, layout::kAttrSource, header.source);
    h5::WriteStringAttribute(file, layout::kAttrSourcePath, header.source_path);
    h5::WriteStringAttribute(file, layout::kAttrToolVersion, kToolVersion);
    h5::WriteStringAttribute(file, layout::kAttrCreatedUtc, UtcNowIso8601());

    if (header.colour_size)
      impl_->streams[0] = CreateStream(file, layout::kColour, *header.colour_size, true, options, std::nullopt);
    if (header.depth_size) {
      impl_->streams[1] =
          CreateStream(file, layout::kDepth, *header.depth_size, false, options, InvalidDepthValue(header.depth_units));
      h5::WriteStringAttribute(impl_->streams[1]->frames, layout::kAttrUnits, ToString(header.depth_units));
      h5::WriteIntAttribute(impl_->streams[1]->frames, layout::kAttrInvalidValue,
                            InvalidDepthValue(header.depth_units));
    }
    if (header.ir_size) impl_->streams[2] = CreateStream(file, layout::kIr, *header.ir_size, false, options, 0);

    using P = H5::PredType;
    const H5::Group root = file.openGroup("/");
    impl_->source_number =
        CreateGrowing(root, layout::kSourceNumber, P::STD_I64LE, P::NATIVE_INT64, {}, kSeriesChunkFrames);
    if (header.has_accel) {
      const H5::Group g = file.createGroup(layout::kAccel);
      impl_->accel = Impl::Accel{
          CreateGrowing(g, layout::kHostTimeNs, P::STD_I64LE, P::NATIVE_INT64, {}, kSeriesChunkFrames),
          CreateGrowing(g, layout::kDeviceTimestamp, P::STD_U64LE, P::NATIVE_UINT64, {}, kSeriesChunkFrames),
          CreateGrowing(g, layout::kAccelCounts, P::STD_I16LE, P::NATIVE_INT16, {3}, kSeriesChunkFrames),
          CreateGrowing(g, layout::kAccelTiltAngle, P::STD_I8LE, P::NATIVE_INT8, {}, kSeriesChunkFrames),
          CreateGrowing(g, layout::kAccelTiltStatus, P::STD_I8LE, P::NATIVE_INT8, {}, kSeriesChunkFrames)};
    }
    if (!header.device_registration_json.empty()) {
      const H5::Group g = file.createGroup(layout::kDevice);
      h5::WriteStringAttribute(g, layout::kAttrRegistrationJson, header.device_registration_json);
    }
    if (!header.scenario_json.empty()) {
      const H5::Group g = file.createGroup(layout::kTruth);
      h5::WriteStringAttribute(g, layout::kAttrScenarioJson, header.scenario_json);
    }
    for (const auto& s : header.series) {
      // Create intermediate groups ("truth/..."), then the dataset.
      const auto slash = s.path.rfind('/');
      const std::string group_path = slash == std::string::npos ? "/" : s.path.substr(0, slash);
      if (!h5::Exists(file, group_path) && group_path != "/") file.createGroup(group_path);
      std::vector<hsize_t> shape(s.shape.begin(), s.shape.end());
      GrowingDataset d = CreateGrowing(file.openGroup(group_path), s.path.substr(slash + 1), P::IEEE_F64LE,
                                       P::NATIVE_DOUBLE, shape, 64);
      if (!s.description.empty()) h5::WriteStringAttribute(d.dataset, "description", s.description);
      impl_->series.emplace_back(s, std::move(d));
    }
    file.flush(H5F_SCOPE_GLOBAL);
    if (H5Fstart_swmr_write(file.getId()) < 0) {
      throw std::runtime_error(path_.string() + ": HDF5 refused to start SWMR writing");
    }
  } catch (const H5::Exception& e) {
    h5::ThrowWriteFailure(path_, "creating the recording failed (" + e.getDetailMsg() + ")");
  }
}

RecordingWriter::~RecordingWriter() {
  try {
    Close();
  } catch (...) {
    // A destructor must not throw; the file stays readable up to the last flush.
  }
}

EncodedFramePair RecordingWriter::Encode(FramePair frame) const {
  static constexpr const char* kNames[3] = {layout::kColour, layout::kDepth, layout::kIr};
  EncodedFramePair out;
  StreamFrame* frames[3] = {&frame.colour, &frame.depth, &frame.ir};
  for (int i = 0; i < 3; ++i) {
    const auto& image = frames[i]->image;
    if (image.empty()) continue;
    const auto& stream = impl_->streams[i];
    if (!stream) {
      throw InputError(std::string("frame ") + std::to_string(frame.source_number) + ": has a " + kNames[i] +
                       " image but the recording declares no " + kNames[i] + " stream");
    }
    if (image.size() != stream->size || image.type() != stream->cv_type) {
      throw InputError(std::string("frame ") + std::to_string(frame.source_number) + ": " + kNames[i] + " image is " +
                       std::to_string(image.cols) + "x" + std::to_string(image.rows) + " of type " +
                       std::to_string(image.type()) + ", expected " + std::to_string(stream->size.width) + "x" +
                       std::to_string(stream->size.height) + " of type " + std::to_string(stream->cv_type));
    }
  }
  for (const auto& [s, d] : impl_->series) {
    const auto it = frame.series.find(s.path);
    std::size_t expected = 1;
    for (int n : s.shape) expected *= static_cast<std::size_t>(n);
    if (it == frame.series.end() || it->second.size() != expected) {
      throw std::logic_error("frame lacks per-frame series " + s.path + " of " + std::to_string(expected) + " values");
    }
  }
  auto encode = [&](int i) {
    if (!impl_->streams[i] || frames[i]->image.empty()) return;
    const cv::Mat image = frames[i]->image.isContinuous() ? frames[i]->image : frames[i]->image.clone();
    out.chunks[i] = impl_->streams[i]->codec.Encode(image.data, image.total() * image.elemSize());
  };
  tbb::parallel_invoke([&] { encode(0); }, [&] { encode(1); }, [&] { encode(2); });
  for (auto* f : frames) f->image.release();
  out.meta = std::move(frame);
  return out;
}

void RecordingWriter::Append(EncodedFramePair frame) {
  h5::SilenceLibraryErrors();  // per thread: frames are written on a flow graph's thread
  if (impl_->closed) throw std::logic_error("append to a closed recording");
  const auto index = static_cast<hsize_t>(frames_);
  const StreamFrame* metas[3] = {&frame.meta.colour, &frame.meta.depth, &frame.meta.ir};
  for (int i = 0; i < 3; ++i) {
    auto& stream = impl_->streams[i];
    if (!stream) continue;
    std::vector<hsize_t>& dims = stream->frame_dims;
    dims[0] = index + 1;
    stream->frames.extend(dims.data());
    const std::uint8_t valid = frame.chunks[i].has_value();
    if (valid) {
      std::vector<hsize_t> offset(dims.size(), 0);
      offset[0] = index;
      const auto& chunk = *frame.chunks[i];
      if (H5Dwrite_chunk(stream->frames.getId(), H5P_DEFAULT, chunk.filter_mask, offset.data(), chunk.size,
                         chunk.bytes.get()) < 0) {
        h5::ThrowWriteFailure(path_, "writing frame " + std::to_string(index) + " failed");
      }
    }
    stream->valid.AppendEntry(&valid);
    stream->device_timestamp.AppendEntry(&metas[i]->device_timestamp);
    stream->host_time_ns.AppendEntry(&metas[i]->host_time_ns);
  }
  impl_->source_number.AppendEntry(&frame.meta.source_number);
  for (auto& [s, d] : impl_->series) d.AppendEntry(frame.meta.series.at(s.path).data());
  if (impl_->accel) {
    for (const AccelSample& a : frame.meta.accel) {
      impl_->accel->host_time_ns.AppendEntry(&a.host_time_ns);
      impl_->accel->device_timestamp.AppendEntry(&a.device_timestamp);
      impl_->accel->counts.AppendEntry(a.counts.data());
      impl_->accel->tilt_angle.AppendEntry(&a.tilt_angle);
      impl_->accel->tilt_status.AppendEntry(&a.tilt_status);
    }
  }
  ++frames_;
  // The first frame is flushed at once: a disk that fills before the first
  // interval ends (a simulator renders frames in milliseconds) otherwise
  // left a file whose structure was never on disk, which no reader opens
  // (issue 47's outside probe).
  if (frames_ == 1 || std::chrono::steady_clock::now() - impl_->last_flush >= impl_->options.flush_interval) Flush();
}

void RecordingWriter::Flush() {
  h5::SilenceLibraryErrors();
  try {
    for (auto& stream : impl_->streams) {
      if (!stream) continue;
      stream->valid.WritePending();
      stream->device_timestamp.WritePending();
      stream->host_time_ns.WritePending();
    }
    impl_->source_number.WritePending();
    for (auto& [s, d] : impl_->series) d.WritePending();
    if (impl_->accel) {
      for (GrowingDataset* d : {&impl_->accel->host_time_ns, &impl_->accel->device_timestamp, &impl_->accel->counts,
                                &impl_->accel->tilt_angle, &impl_->accel->tilt_status}) {
        d->WritePending();
      }
    }
    impl_->file->flush(H5F_SCOPE_GLOBAL);
  } catch (const H5::Exception& e) {
    h5::ThrowWriteFailure(path_,
                          "writing frames up to " + std::to_string(frames_) + " failed (" + e.getDetailMsg() + ")");
  }
  impl_->last_flush = std::chrono::steady_clock::now();
}

namespace {

// Closes once and drops the id whether or not the close succeeds (H5Dclose
// and H5Gclose release an id even when its flush fails), so no destructor
// tries again or prints.
template <typename Object>  // H5::DataSet or H5::Group
void CloseQuietly(Object& object) {
  try {
    object.close();
  } catch (const H5::Exception&) {
  }
}

}  // namespace

void RecordingWriter::Impl::CloseDatasets() {
  for (auto& stream : streams) {
    if (!stream) continue;
    for (H5::DataSet* d :
         {&stream->frames, &stream->valid.dataset, &stream->device_timestamp.dataset, &stream->host_time_ns.dataset})
      CloseQuietly(*d);
    CloseQuietly(stream->group);
  }
  streams = {};
  for (auto& [s, d] : series) CloseQuietly(d.dataset);
  series.clear();
  if (accel) {
    for (GrowingDataset* d :
         {&accel->host_time_ns, &accel->device_timestamp, &accel->counts, &accel->tilt_angle, &accel->tilt_status})
      CloseQuietly(d->dataset);
  }
  accel.reset();
  CloseQuietly(source_number.dataset);
  source_number = {};
}

std::optional<std::string> RecordingWriter::Impl::CloseAll() {
  CloseDatasets();
  try {
    file->close();
  } catch (const H5::Exception& e) {
    h5::AbandonFile(std::move(file));
    return e.getDetailMsg();
  }
  return std::nullopt;
}

// A failed flush or close (a full disk) still closes every object once, so
// the frames flushed before stay readable and nothing touches the file again.
void RecordingWriter::Close() {
  if (impl_->closed) return;
  impl_->closed = true;
  std::exception_ptr failure;
  try {
    Flush();
  } catch (...) {
    failure = std::current_exception();
  }
  if (const auto error = impl_->CloseAll(); error && !failure) {
    try {
      h5::ThrowWriteFailure(path_, "closing the recording failed (" + *error + ")");
    } catch (...) {
      failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
  SyncPath(path_);
}

}  // namespace speckle
