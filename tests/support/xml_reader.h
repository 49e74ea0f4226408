// A small XML reader for the tests of JUnit output: the document is parsed, not pattern-matched, and anything not well-formed is refused.
#pragma once

#include <cctype>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace tippe::fixtures {

struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::vector<std::unique_ptr<XmlElement>> children;
  std::string text;
  std::vector<const XmlElement*> all(const std::string& n) const {
    std::vector<const XmlElement*> out;
    if (name == n) out.push_back(this);
    for (const auto& c : children)
      for (const XmlElement* e : c->all(n)) out.push_back(e);
    return out;
  }
};

// Throws std::runtime_error on anything that is not well-formed (unbalanced tags, a raw '<' or a
// stray '&' in text or attributes, an unknown entity, control characters).
class XmlReader {
 public:
  explicit XmlReader(std::string s) : s_(std::move(s)) {}
  std::unique_ptr<XmlElement> document() {
    skip_space();
    if (s_.compare(i_, 5, "<?xml") == 0) {
      const size_t end = s_.find("?>", i_);
      if (end == std::string::npos) fail("unterminated prolog");
      i_ = end + 2;
    }
    skip_space();
    auto root = element();
    skip_space();
    if (i_ != s_.size()) fail("content after the root element");
    return root;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error("XML at " + std::to_string(i_) + ": " + why);
  }
  void skip_space() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  std::string name() {
    const size_t b = i_;
    while (i_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[i_])) || s_[i_] == '_' || s_[i_] == '-' ||
                              s_[i_] == ':' || s_[i_] == '.'))
      ++i_;
    if (b == i_) fail("expected a name");
    return s_.substr(b, i_ - b);
  }
  // Character data up to `stop`, entities decoded.
  std::string chars(char stop) {
    std::string out;
    while (i_ < s_.size() && s_[i_] != stop) {
      const char c = s_[i_];
      if (c == '<') fail("raw '<' in character data");
      if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t' && c != '\r') fail("control character");
      if (c == '&') {
        const size_t semi = s_.find(';', i_);
        if (semi == std::string::npos) fail("stray '&'");
        const std::string ent = s_.substr(i_ + 1, semi - i_ - 1);
        static const std::map<std::string, std::string> named = {
            {"amp", "&"}, {"lt", "<"}, {"gt", ">"}, {"quot", "\""}, {"apos", "'"}};
        if (auto it = named.find(ent); it != named.end())
          out += it->second;
        else if (ent.size() > 1 && ent[0] == '#')
          out += static_cast<char>(ent[1] == 'x' ? std::stoi(ent.substr(2), nullptr, 16) : std::stoi(ent.substr(1)));
        else
          fail("unknown entity &" + ent + ";");
        i_ = semi + 1;
        continue;
      }
      out += c;
      ++i_;
    }
    return out;
  }
  std::unique_ptr<XmlElement> element() {
    if (i_ >= s_.size() || s_[i_] != '<') fail("expected '<'");
    ++i_;
    auto e = std::make_unique<XmlElement>();
    e->name = name();
    for (;;) {
      skip_space();
      if (s_.compare(i_, 2, "/>") == 0) {
        i_ += 2;
        return e;
      }
      if (i_ < s_.size() && s_[i_] == '>') {
        ++i_;
        break;
      }
      const std::string key = name();
      skip_space();
      if (i_ >= s_.size() || s_[i_] != '=') fail("expected '='");
      ++i_;
      skip_space();
      if (i_ >= s_.size() || s_[i_] != '"') fail("expected '\"'");
      ++i_;
      const std::string value = chars('"');
      if (i_ >= s_.size()) fail("unterminated attribute");
      ++i_;
      if (!e->attrs.emplace(key, value).second) fail("repeated attribute " + key);
    }
    for (;;) {
      e->text += chars('<');
      if (i_ >= s_.size()) fail("unterminated element " + e->name);
      if (s_.compare(i_, 2, "</") == 0) {
        i_ += 2;
        if (name() != e->name) fail("mismatched end tag for " + e->name);
        skip_space();
        if (i_ >= s_.size() || s_[i_] != '>') fail("expected '>'");
        ++i_;
        return e;
      }
      e->children.push_back(element());
    }
  }
  std::string s_;
  size_t i_ = 0;
};

inline std::unique_ptr<XmlElement> parse_xml(const std::string& text) { return XmlReader(text).document(); }

}  // namespace tippe::fixtures
