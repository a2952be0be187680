#pragma once
// Structured mutations of an HDF5 file through the HDF5 API, not only its
// bytes: the fuzzer's bytes are read as operations on the file's datasets and
// attributes (delete one; replace it with another type, rank or length; fill
// it with NaN, infinities, negative or huge values; set an attribute to
// another type or value), then a few raw byte flips. A reader meets what a
// damaged, hand-edited or foreign file can hold.
#include <H5Cpp.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace speckle::fuzz {

class FuzzBytes {
 public:
  FuzzBytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  std::uint8_t Next() { return pos_ < size_ ? data_[pos_++] : 0; }

 private:
  const std::uint8_t* data_;
  std::size_t size_, pos_ = 0;
};

struct H5Object {
  std::string path;
  bool dataset = false;
};

inline herr_t CollectObject(hid_t, const char* name, const H5O_info_t* info, void* out) {
  if (std::string(name) == ".") return 0;
  static_cast<std::vector<H5Object>*>(out)->push_back({"/" + std::string(name), info->type == H5O_TYPE_DATASET});
  return 0;
}

inline double SpecialValue(std::uint8_t pick) {
  const double values[] = {std::nan(""), INFINITY, -INFINITY, -1, 0, 1e308, -1e308, 4e9, 2047, 65535, 1e-300, 0.5};
  return values[pick % (sizeof values / sizeof values[0])];
}

inline H5::DataType PickType(std::uint8_t pick) {
  switch (pick % 7) {
    case 0:
      return H5::PredType::NATIVE_DOUBLE;
    case 1:
      return H5::PredType::NATIVE_FLOAT;
    case 2:
      return H5::PredType::NATIVE_INT8;
    case 3:
      return H5::PredType::NATIVE_UINT16;
    case 4:
      return H5::PredType::NATIVE_INT64;
    case 5:
      return H5::PredType::NATIVE_UINT8;
    default:
      return H5::StrType(H5::PredType::C_S1, 8);
  }
}

inline void ReplaceDataset(H5::H5File& file, const std::string& path, FuzzBytes& in) {
  const H5::DataType type = PickType(in.Next());
  const int rank = 1 + in.Next() % 3;
  std::vector<hsize_t> dims;
  hsize_t n = 1;
  for (int r = 0; r < rank; ++r) dims.push_back(in.Next() % 9), n *= dims.back();
  file.unlink(path);
  const H5::DataSpace space(rank, dims.data());
  H5::DataSet set = file.createDataSet(path, type, space);
  if (n == 0) return;
  if (type.getClass() == H5T_STRING) {
    std::vector<char> text(n * 8, 'x');
    set.write(text.data(), type);
    return;
  }
  std::vector<double> values(n);
  for (auto& v : values) v = SpecialValue(in.Next());
  set.write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

inline void FillDataset(H5::H5File& file, const std::string& path, FuzzBytes& in) {
  H5::DataSet set = file.openDataSet(path);
  if (set.getTypeClass() != H5T_INTEGER && set.getTypeClass() != H5T_FLOAT) return;
  const hssize_t n = set.getSpace().getSimpleExtentNpoints();
  if (n <= 0 || n > (1 << 22)) return;
  std::vector<double> values(static_cast<std::size_t>(n));
  set.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  const double special = SpecialValue(in.Next());
  const std::size_t every = 1 + in.Next() % 8;
  for (std::size_t i = in.Next() % values.size(); i < values.size(); i += every) values[i] = special;
  set.write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

inline void SetAttribute(H5::H5File& file, const std::string& object, FuzzBytes& in) {
  H5::H5Object* target = nullptr;
  H5::Group group;
  H5::DataSet set;
  try {
    set = file.openDataSet(object);
    target = &set;
  } catch (const H5::Exception&) {
    group = file.openGroup(object);
    target = &group;
  }
  if (target->getNumAttrs() == 0) return;
  const std::string name = target->openAttribute(static_cast<unsigned>(in.Next() % target->getNumAttrs())).getName();
  target->removeAttr(name);
  if (in.Next() % 3 == 0) return;  // deleted
  const H5::DataSpace scalar;
  if (in.Next() % 2) {
    const double v = SpecialValue(in.Next());
    target->createAttribute(name, PickType(in.Next() % 6), scalar).write(H5::PredType::NATIVE_DOUBLE, &v);
  } else {
    const H5::StrType text(H5::PredType::C_S1, 6);
    const char* const words[] = {"abcdef", "\xff\xfe{[[[", "planar", "9e9999"};
    target->createAttribute(name, text, scalar).write(text, words[in.Next() % 4]);
  }
}

// Mutates the HDF5 file at `path` as the fuzzer's bytes say. Returns false
// when the file could not be mutated (then there is nothing new to read).
inline bool MutateH5(const std::string& path, FuzzBytes& in) {
  try {
    H5::H5File file(path, H5F_ACC_RDWR);
    std::vector<H5Object> objects{{"/", false}};
    H5Ovisit(file.getId(), H5_INDEX_NAME, H5_ITER_NATIVE, CollectObject, &objects);
    for (int op = 0, ops = 1 + in.Next() % 4; op < ops && !in.empty(); ++op) {
      const H5Object& o = objects[in.Next() % objects.size()];
      const int kind = in.Next() % 4;
      if (o.dataset && kind == 0) {
        file.unlink(o.path);
        objects.erase(objects.begin() + (&o - objects.data()));
      } else if (o.dataset && kind == 1) {
        ReplaceDataset(file, o.path, in);
      } else if (o.dataset && kind == 2) {
        FillDataset(file, o.path, in);
      } else {
        SetAttribute(file, o.path, in);
      }
    }
  } catch (const H5::Exception&) {
    return false;
  }
  return true;
}

}  // namespace speckle::fuzz
