#include "recorder/chunk_codec.h"

// libaec's szlib.h declares C functions without extern "C".
extern "C" {
#include <szlib.h>
}
#include <lz4.h>
#include <zlib.h>

#include <cstring>
#include <stdexcept>

#include "schemas/errors.h"

namespace speckle {
namespace {

constexpr H5Z_filter_t kLz4FilterId = 32004;  // registered with The HDF Group

std::vector<std::uint8_t> Shuffled(const std::uint8_t* data, std::size_t bytes, std::size_t element_size) {
  std::vector<std::uint8_t> shuffled(bytes);
  const std::size_t n = bytes / element_size;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t b = 0; b < element_size; ++b) shuffled[b * n + i] = data[i * element_size + b];
  return shuffled;
}

void PutBigEndian(std::uint8_t* out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out[i] = static_cast<std::uint8_t>(value >> (8 * (bytes - 1 - i)));
}

}  // namespace

std::string ToString(Codec codec) {
  switch (codec) {
    case Codec::kSzip:
      return "szip";
    case Codec::kDeflate:
      return "deflate";
    case Codec::kNone:
      return "none";
    case Codec::kLz4:
      return "lz4";
  }
  return "?";
}

Codec CodecFromString(const std::string& text) {
  if (text == "szip") return Codec::kSzip;
  if (text == "deflate") return Codec::kDeflate;
  if (text == "none") return Codec::kNone;
  if (text == "lz4") return Codec::kLz4;
  throw InputError("unknown codec \"" + text + "\" (expected szip, deflate, lz4 or none)");
}

void ChunkCodec::AddFilters(hid_t dcpl, Codec codec, int deflate_level) {
  switch (codec) {
    case Codec::kSzip:
      H5Pset_szip(dcpl, H5_SZIP_NN_OPTION_MASK, 32);
      break;
    case Codec::kDeflate:
      H5Pset_shuffle(dcpl);
      H5Pset_deflate(dcpl, static_cast<unsigned>(deflate_level));
      break;
    case Codec::kLz4:
      // Optional: the dataset can be created even where the plugin is
      // missing; we write the chunks ourselves.
      H5Pset_shuffle(dcpl);
      H5Pset_filter(dcpl, kLz4FilterId, H5Z_FLAG_OPTIONAL, 0, nullptr);
      break;
    case Codec::kNone:
      break;
  }
}

ChunkCodec ChunkCodec::ForDataset(hid_t dataset, Codec codec, int deflate_level) {
  ChunkCodec c;
  c.codec_ = codec;
  c.deflate_level_ = deflate_level;
  const hid_t type = H5Dget_type(dataset);
  c.element_size_ = H5Tget_size(type);
  H5Tclose(type);
  const hid_t dcpl = H5Dget_create_plist(dataset);
  c.filter_count_ = H5Pget_nfilters(dcpl);
  if (codec == Codec::kSzip) {
    // After creation the list holds the "local" parameters HDF5 computed
    // (bits per pixel, scanline, byte order); the decoder will use them.
    unsigned flags = 0;
    std::size_t count = 4;
    if (H5Pget_filter_by_id2(dcpl, H5Z_FILTER_SZIP, &flags, &count, c.szip_params_, 0, nullptr, nullptr) < 0 ||
        count != 4) {
      H5Pclose(dcpl);
      throw std::runtime_error("HDF5 did not report szip parameters for a new dataset");
    }
  }
  H5Pclose(dcpl);
  return c;
}

EncodedChunk ChunkCodec::Encode(const std::uint8_t* data, std::size_t bytes) const {
  EncodedChunk out;
  const auto store_raw = [&] {
    // Incompressible: store as is and mark every filter as skipped.
    out.bytes.reset(new std::uint8_t[bytes]);
    std::memcpy(out.bytes.get(), data, bytes);
    out.size = bytes;
    out.filter_mask = filter_count_ ? (1u << filter_count_) - 1 : 0;
  };
  switch (codec_) {
    case Codec::kNone:
      store_raw();
      return out;
    case Codec::kSzip: {
      SZ_com_t params{};
      params.options_mask = static_cast<int>(szip_params_[0]);
      params.pixels_per_block = static_cast<int>(szip_params_[1]);
      params.bits_per_pixel = static_cast<int>(szip_params_[2]);
      params.pixels_per_scanline = static_cast<int>(szip_params_[3]);
      // HDF5's szip chunk: little-endian uint32 raw size, then the stream.
      out.bytes.reset(new std::uint8_t[bytes + 4]);
      const auto size = static_cast<std::uint32_t>(bytes);
      for (int i = 0; i < 4; ++i) out.bytes[i] = static_cast<std::uint8_t>(size >> (8 * i));
      std::size_t compressed = bytes;
      if (SZ_BufftoBuffCompress(out.bytes.get() + 4, &compressed, data, bytes, &params) != SZ_OK ||
          compressed >= bytes) {
        store_raw();
        return out;
      }
      out.size = compressed + 4;
      return out;
    }
    case Codec::kLz4: {
      // The LZ4 plugin's chunk: big-endian uint64 raw size, uint32 block
      // size, then per block a big-endian uint32 compressed size and the
      // block (one block per frame here).
      // Shuffling one-byte elements (colour) changes nothing: compress in place.
      const std::vector<std::uint8_t> shuffled =
          element_size_ > 1 ? Shuffled(data, bytes, element_size_) : std::vector<std::uint8_t>();
      const std::uint8_t* input = element_size_ > 1 ? shuffled.data() : data;
      const int bound = LZ4_compressBound(static_cast<int>(bytes));
      out.bytes.reset(new std::uint8_t[16 + static_cast<std::size_t>(bound)]);
      const int compressed =
          LZ4_compress_default(reinterpret_cast<const char*>(input), reinterpret_cast<char*>(out.bytes.get() + 16),
                               static_cast<int>(bytes), bound);
      if (compressed <= 0 || static_cast<std::size_t>(compressed) + 16 >= bytes) {
        store_raw();
        return out;
      }
      PutBigEndian(out.bytes.get(), bytes, 8);
      PutBigEndian(out.bytes.get() + 8, bytes, 4);
      PutBigEndian(out.bytes.get() + 12, static_cast<std::uint64_t>(compressed), 4);
      out.size = 16 + static_cast<std::size_t>(compressed);
      return out;
    }
    case Codec::kDeflate: {
      const std::vector<std::uint8_t> shuffled = Shuffled(data, bytes, element_size_);
      uLongf compressed = compressBound(bytes);
      out.bytes.reset(new std::uint8_t[compressed]);
      if (compress2(out.bytes.get(), &compressed, shuffled.data(), bytes, deflate_level_) != Z_OK ||
          compressed >= bytes) {
        store_raw();
        return out;
      }
      out.size = compressed;
      return out;
    }
  }
  return out;
}

}  // namespace speckle
