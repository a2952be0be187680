#pragma once
// Writes small libfreenect `record` (fakenect) dumps and frame files the way
// the real recorder does, so tests control every byte of their input.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace speckle::testing {

inline void WriteFile(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// A 16-bit PGM whose every pixel holds `value`.
inline std::string DepthPgm(int width, int height, int maxval, bool little_endian, std::uint16_t value) {
  std::string data = "P5 " + std::to_string(width) + " " + std::to_string(height) + " " + std::to_string(maxval) + "\n";
  for (int i = 0; i < width * height; ++i) {
    const char lo = static_cast<char>(value & 0xff), hi = static_cast<char>(value >> 8);
    data += little_endian ? std::string{lo, hi} : std::string{hi, lo};
  }
  return data;
}

// A small valid fakenect dump: `depth` frames at 30 Hz, optional colour;
// every depth pixel holds `raw` (so tests can tell two dumps apart).
inline std::filesystem::path MakeDump(const std::filesystem::path& dir, int depth, int colour,
                                      double colour_offset_s = 0.001, std::uint16_t raw = 700) {
  std::filesystem::create_directories(dir);
  std::string index;
  for (int i = 0; i < std::max(depth, colour); ++i) {
    const double t = 1000.0 + i / 30.0;
    if (i < depth) {
      const std::string name = "d-" + std::to_string(t) + "-" + std::to_string(1000 + i) + ".pgm";
      WriteFile(dir / name, DepthPgm(640, 480, 65535, true, raw));
      index += name + "\n";
    }
    if (i < colour) {
      const std::string name = "r-" + std::to_string(t + colour_offset_s) + "-" + std::to_string(1000 + i) + ".ppm";
      WriteFile(dir / name, "P6 640 480 255\n" + std::string(640 * 480 * 3, '\x40'));
      index += name + "\n";
    }
  }
  WriteFile(dir / "INDEX.txt", index);
  return dir;
}

}  // namespace speckle::testing
