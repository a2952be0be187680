#pragma once
// Text put into an HTML page's body or an attribute's quotes: the reports
// (check.html, fleet.html) show names and messages a user or a file chose.
#include <string>
#include <string_view>

namespace speckle {

inline std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace speckle
