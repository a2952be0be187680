#pragma once
// The few HDF5 operations recordings and artifacts need, behind names that
// say what they do and errors that say which file, object and attribute was
// at fault.
#include <H5Cpp.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "schemas/errors.h"

namespace speckle::h5 {

// Silences HDF5's own stderr error stacks; we report errors ourselves.
void SilenceLibraryErrors();

bool Exists(const H5::H5Location& parent, const std::string& path);

// A file whose close failed (a full disk: the close flushes metadata). HDF5
// 1.10.8 (Debian 12's) frees such a file but keeps its id (HDFFV-11052, fixed
// upstream by HDFGroup/hdf5 pull request 2291, later than 1.10.8), so closing
// it again, or the library's own shutdown at exit, reads freed memory
// (SIGSEGV: the backtrace ends in H5F__close_cb from H5_term_library). The file's wrapper is never destroyed, and
// the tools' main (apps/cli_main.h) then ends without HDF5's shutdown. The
// OS closes the descriptor; what was flushed before stays readable.
void AbandonFile(std::unique_ptr<H5::H5File> file);
bool AnyFileAbandoned();

// What a failed write throws: a filesystem_error (no space left on the
// device) naming the file when its disk has under 64 MiB free, else a
// runtime_error naming it.
[[noreturn]] void ThrowWriteFailure(const std::filesystem::path& file, const std::string& what);

void WriteStringAttribute(const H5::H5Object& object, const std::string& name, const std::string& value);
void WriteIntAttribute(const H5::H5Object& object, const std::string& name, long long value);

// Readers throw InputError "<file>: <object>: attribute '<name>' ..." when the
// attribute is missing or of the wrong kind.
std::string ReadStringAttribute(const H5::H5Object& object, const std::string& name, const std::string& where);
long long ReadIntAttribute(const H5::H5Object& object, const std::string& name, const std::string& where);

std::vector<hsize_t> Dimensions(const H5::DataSet& dataset);

template <typename T>
void WriteVector(H5::Group& group, const std::string& name, const std::vector<T>& values, const H5::PredType& type,
                 const std::vector<hsize_t>& dims) {
  const H5::DataSpace space(static_cast<int>(dims.size()), dims.data());
  group.createDataSet(name, type, space).write(values.data(), type);
}

// A whole dataset, flattened; InputError "<where>: missing dataset /<name>".
template <typename T>
std::vector<T> ReadVector(const H5::H5File& file, const std::string& name, const H5::PredType& type,
                          const std::string& where) {
  if (!Exists(file, name)) throw InputError(where + ": missing dataset /" + name);
  try {
    const H5::DataSet d = file.openDataSet(name);
    const H5T_class_t kind = d.getTypeClass();
    if (kind != H5T_INTEGER && kind != H5T_FLOAT)
      throw InputError(where + ": /" + name + ": expected numbers, found another type");
    std::size_t n = 1;
    for (hsize_t dim : Dimensions(d)) n *= dim;
    if (n > (std::size_t{1} << 31))
      throw InputError(where + ": /" + name + ": " + std::to_string(n) + " values, more than any artifact holds");
    std::vector<T> values(n);
    if (n) d.read(values.data(), type);
    return values;
  } catch (const H5::Exception& e) {
    throw InputError(where + ": /" + name + ": cannot be read (" + e.getDetailMsg() + ")");
  }
}

}  // namespace speckle::h5
