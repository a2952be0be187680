#include "schemas/h5_access.h"

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
