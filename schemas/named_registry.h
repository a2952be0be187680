#pragma once
// A catalogue filled by name at static initialisation: each effect header
// (simulator or model) registers itself, so adding one touches no other file.
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace speckle {

template <class Info>  // Info has a std::string `name`
class NamedRegistry {
 public:
  static bool Add(Info info, const std::string& kind) {
    const std::string name = info.name;
    if (!Map().emplace(name, std::move(info)).second) throw std::logic_error(kind + " registered twice: " + name);
    return true;
  }
  // Sorted by name.
  static std::vector<Info> All() {
    std::vector<Info> all;
    for (const auto& [name, info] : Map()) all.push_back(info);
    return all;
  }
  static const Info* Find(const std::string& name) {
    const auto it = Map().find(name);
    return it == Map().end() ? nullptr : &it->second;
  }
  static std::string Names() {  // "a, b, c", for messages
    std::string names;
    for (const auto& [name, info] : Map()) names += (names.empty() ? "" : ", ") + name;
    return names;
  }

 private:
  static std::map<std::string, Info>& Map() {
    static std::map<std::string, Info> map;
    return map;
  }
};

}  // namespace speckle
