#pragma once
// The few HDF5 operations recordings need, behind names that say what they
// do and errors that say which file, object and attribute was at fault.
#include <H5Cpp.h>

#include <string>
#include <vector>

namespace speckle::h5 {

// Silences HDF5's own stderr error stacks; we report errors ourselves.
void SilenceLibraryErrors();

bool Exists(const H5::H5Location& parent, const std::string& path);

void WriteStringAttribute(const H5::H5Object& object, const std::string& name, const std::string& value);
void WriteIntAttribute(const H5::H5Object& object, const std::string& name, long long value);

// Readers throw InputError "<file>: <object>: attribute '<name>' ..." when the
// attribute is missing or of the wrong kind.
std::string ReadStringAttribute(const H5::H5Object& object, const std::string& name, const std::string& where);
long long ReadIntAttribute(const H5::H5Object& object, const std::string& name, const std::string& where);

std::vector<hsize_t> Dimensions(const H5::DataSet& dataset);

}  // namespace speckle::h5
