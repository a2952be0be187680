#pragma once
// A Python literal (dicts, lists, tuples, strings, numbers, True / False /
// None, # comments) as JSON: an mrcal .cameramodel is one, read by mrcal
// with ast.literal_eval. Bytes (b'...') read as strings. Throws InputError
// naming `origin` where the text is not such a literal.
#include <nlohmann/json.hpp>
#include <string>

namespace speckle::formats {

nlohmann::json PythonLiteralToJson(const std::string& text, const std::string& origin);

}  // namespace speckle::formats
