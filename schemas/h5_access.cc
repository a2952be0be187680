#include "schemas/h5_access.h"

#include <fmt/format.h>

#include <atomic>
#include <system_error>

#include "schemas/errors.h"

namespace speckle::h5 {

// On the calling thread only: Debian's HDF5 is thread-safe and keeps this
// setting per thread, so each reader calls it where it reads (a frame read on
// a TBB worker printed HDF5's whole error stack).
void SilenceLibraryErrors() {
  thread_local bool silenced = false;  // nothing turns it back on: once per thread
  if (silenced) return;
  H5::Exception::dontPrint();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  silenced = true;
}

namespace {
std::atomic<bool> abandoned{false};
}  // namespace

void AbandonFile(std::unique_ptr<H5::H5File> file) {
  abandoned = true;
  static_cast<void>(file.release());  // deliberately never destroyed: see the header
}

bool AnyFileAbandoned() { return abandoned; }

void ThrowWriteFailure(const std::filesystem::path& file, const std::string& what) {
  std::error_code error;
  const auto space = std::filesystem::space(file.parent_path().empty() ? "." : file.parent_path(), error);
  if (!error && space.available < (std::uintmax_t{64} << 20)) {
    throw std::filesystem::filesystem_error(
        fmt::format("{}: the disk is full ({} kB free)", what, space.available >> 10), file,
        std::make_error_code(std::errc::no_space_on_device));
  }
  throw std::runtime_error(file.string() + ": " + what);
}

bool Exists(const H5::H5Location& parent, const std::string& path) {
  // H5Lexists fails (rather than answering false) when an intermediate group
  // is missing, so walk the path one link at a time.
  std::string prefix;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t end = path.find('/', start);
    prefix += (prefix.empty() ? "" : "/") + path.substr(start, end - start);
    if (H5Lexists(parent.getId(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return true;
}

void WriteStringAttribute(const H5::H5Object& object, const std::string& name, const std::string& value) {
  const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  H5::Attribute attribute = object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
  attribute.write(type, value);
}

void WriteIntAttribute(const H5::H5Object& object, const std::string& name, long long value) {
  H5::Attribute attribute = object.createAttribute(name, H5::PredType::STD_I64LE, H5::DataSpace(H5S_SCALAR));
  attribute.write(H5::PredType::NATIVE_LLONG, &value);
}

namespace {
H5::Attribute OpenAttribute(const H5::H5Object& object, const std::string& name, const std::string& where) {
  if (!object.attrExists(name)) throw InputError(where + ": missing attribute '" + name + "'");
  return object.openAttribute(name);
}
}  // namespace

std::string ReadStringAttribute(const H5::H5Object& object, const std::string& name, const std::string& where) {
  H5::Attribute attribute = OpenAttribute(object, name, where);
  if (attribute.getTypeClass() != H5T_STRING) {
    throw InputError(where + ": attribute '" + name + "' should be a string");
  }
  std::string value;
  attribute.read(attribute.getStrType(), value);
  return value;
}

long long ReadIntAttribute(const H5::H5Object& object, const std::string& name, const std::string& where) {
  H5::Attribute attribute = OpenAttribute(object, name, where);
  if (attribute.getTypeClass() != H5T_INTEGER) {
    throw InputError(where + ": attribute '" + name + "' should be an integer");
  }
  long long value = 0;
  attribute.read(H5::PredType::NATIVE_LLONG, &value);
  return value;
}

std::vector<hsize_t> Dimensions(const H5::DataSet& dataset) {
  const H5::DataSpace space = dataset.getSpace();
  std::vector<hsize_t> dims(static_cast<std::size_t>(space.getSimpleExtentNdims()));
  space.getSimpleExtentDims(dims.data());
  return dims;
}

}  // namespace speckle::h5
