#pragma once
// Compresses one frame into a chunk exactly as HDF5's own filter pipeline
// would, so that chunks can be encoded on worker threads and written with
// H5Dwrite_chunk. Any HDF5 reader (h5py, h5dump) decodes them with the
// standard szip or shuffle+deflate filters, or with the registered LZ4 filter
// plugin (HDF5 looks for it in its plugin folder).
#include <hdf5.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace speckle {

enum class Codec {
  kSzip,     // libaec (szip-compatible), nearest-neighbour predictor: fastest
  kDeflate,  // shuffle + zlib: readable by every HDF5 build, ~3x slower
  kNone,
  kLz4,  // shuffle + LZ4 (filter 32004, Debian's hdf5-filter-plugin): fastest, compresses least
};
std::string ToString(Codec codec);
Codec CodecFromString(const std::string& text);  // throws InputError

struct EncodedChunk {
  // Left uninitialised before the codec writes it: zero-filling a megabyte
  // per frame is measurable at hundreds of frames per second.
  std::unique_ptr<std::uint8_t[]> bytes;
  std::size_t size = 0;
  std::uint32_t filter_mask = 0;  // bit i set = filter i was skipped
};

class ChunkCodec {
 public:
  ChunkCodec() = default;
  // Adds this codec's filters to a dataset creation property list.
  static void AddFilters(hid_t dcpl, Codec codec, int deflate_level);
  // Reads the filter parameters HDF5 settled on for a created dataset.
  static ChunkCodec ForDataset(hid_t dataset, Codec codec, int deflate_level);

  // Thread-safe: no state changes after construction.
  EncodedChunk Encode(const std::uint8_t* data, std::size_t bytes) const;

 private:
  Codec codec_ = Codec::kNone;
  int deflate_level_ = 1;
  std::size_t element_size_ = 1;
  unsigned szip_params_[4] = {};  // HDF5's order: options mask, pixels/block, bits/pixel, pixels/scanline
  int filter_count_ = 0;
};

}  // namespace speckle
