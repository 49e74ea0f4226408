// The one escaper for HTML and XML text (report pages, JUnit files).
#include "harness/io/text.h"

#include "harness/io/scene_io.h"

namespace tippe {

std::string markup_escape(const std::string& text, bool attribute) {
  const std::string s = utf8_replaced(text);
  std::string out;
  out.reserve(s.size());
  for (char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;  // &apos; is not HTML 4; &#39; is both HTML and XML
      case '\n': out += attribute ? "&#10;" : "\n"; break;
      case '\t': out += attribute ? "&#9;" : "\t"; break;
      case '\r': out += "&#13;"; break;
      default:
        if (c < 0x20 || c == 0x7f)
          out += '?';
        else
          out += ch;
    }
  }
  return out;
}

}  // namespace tippe
