// `sogmm view`'s page: the template with the model's bytes (base64) and name.
#include "viewer_page.hpp"

#include <stdexcept>

namespace sogmm::tools {
namespace {

std::string base64(const std::string& in) {
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= in.size(); i += 3) {
    const unsigned v = static_cast<unsigned char>(in[i]) << 16 | static_cast<unsigned char>(in[i + 1]) << 8 |
                       static_cast<unsigned char>(in[i + 2]);
    out += {kAlphabet[v >> 18], kAlphabet[v >> 12 & 63], kAlphabet[v >> 6 & 63], kAlphabet[v & 63]};
  }
  if (i + 1 == in.size()) {
    const unsigned v = static_cast<unsigned char>(in[i]) << 16;
    out += {kAlphabet[v >> 18], kAlphabet[v >> 12 & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    const unsigned v = static_cast<unsigned char>(in[i]) << 16 | static_cast<unsigned char>(in[i + 1]) << 8;
    out += {kAlphabet[v >> 18], kAlphabet[v >> 12 & 63], kAlphabet[v >> 6 & 63], '='};
  }
  return out;
}

// Text for an HTML attribute value in double quotes.
std::string escape_attribute(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      default: out += c;
    }
  }
  return out;
}

// Replaces the first `marker` (the markers precede the viewer's script in the template).
void fill(std::string& page, const std::string& marker, const std::string& value) {
  const std::size_t at = page.find(marker);
  if (at == std::string::npos) throw std::logic_error("viewer page template without " + marker);
  page.replace(at, marker.size(), value);
}

}  // namespace

std::string viewer_page(const std::string& bytes, const std::string& name) {
  std::string page = kViewerPage;
  // Base64 first: a name cannot then bring in a marker (base64 has no '@').
  fill(page, "@@SOGMM_MODEL_BASE64@@", base64(bytes));
  fill(page, "@@SOGMM_FILE_NAME@@", escape_attribute(name));
  return page;
}

}  // namespace sogmm::tools
