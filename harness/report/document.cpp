// One document model for every report page, rendered to Markdown and to one self-contained HTML page.
#include "harness/report/document.h"

#include <cctype>
#include <sstream>

namespace tippe {

void Document::heading(int level, const std::string& text) {
  DocBlock b;
  b.kind = DocBlock::Heading;
  b.level = level;
  b.text = text;
  blocks.push_back(b);
}

void Document::para(const std::string& text, const std::string& css, bool strong) {
  DocBlock b;
  b.kind = DocBlock::Para;
  b.text = text;
  b.css = css;
  b.strong = strong;
  blocks.push_back(b);
}

void Document::list(const std::vector<std::string>& items, const std::string& summary, bool folded) {
  DocBlock b;
  b.kind = DocBlock::List;
  b.items = items;
  b.text = summary;
  b.folded = folded;
  blocks.push_back(b);
}

void Document::table(const DocTable& t, const std::string& summary, bool folded, bool open) {
  DocBlock b;
  b.kind = DocBlock::Table;
  b.table = t;
  b.text = summary;
  b.folded = folded;
  b.open = open;
  blocks.push_back(b);
}

void Document::figure(const std::string& file, const std::string& caption) {
  DocBlock b;
  b.kind = DocBlock::Figure;
  b.file = file;
  b.text = caption;
  blocks.push_back(b);
}

void Document::links(const std::vector<DocLink>& l, const std::string& lead) {
  DocBlock b;
  b.kind = DocBlock::Links;
  b.links = l;
  b.text = lead;
  blocks.push_back(b);
}


namespace {

int toc_entries(const Document& doc) {
  int n = 0;
  for (const DocBlock& b : doc.blocks) n += b.kind == DocBlock::Heading && b.level == 2;
  return n;
}

bool wants_toc(const Document& doc) { return doc.toc_from > 0 && toc_entries(doc) >= doc.toc_from; }

// Where the table of contents goes: before the first level-2 heading (after the verdict).
size_t toc_position(const Document& doc) {
  for (size_t i = 0; i < doc.blocks.size(); ++i)
    if (doc.blocks[i].kind == DocBlock::Heading && doc.blocks[i].level == 2) return i;
  return doc.blocks.size();
}

std::string md_cell(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += "\\|";
    else if (c == '\n') out += ' ';
    else out += c;
  }
  return out;
}

// The anchor GitHub gives a Markdown heading: lower case, spaces to '-', other punctuation dropped.
std::string md_anchor(const std::string& text) {
  std::string out;
  for (unsigned char c : text) {
    if (std::isalnum(c) || c == '-' || c == '_' || c >= 0x80) out += static_cast<char>(std::tolower(c));
    else if (c == ' ') out += '-';
  }
  return out;
}

std::string md_links(const std::vector<DocLink>& links) {
  std::string s;
  for (const DocLink& l : links) s += (s.empty() ? "" : " · ") + ("[" + l.text + "](" + l.href + ")");
  return s;
}

}  // namespace

std::string render_document_markdown(const Document& doc) {
  std::ostringstream os;
  if (!doc.top_links.empty()) os << md_links(doc.top_links) << "\n\n";
  const bool toc = wants_toc(doc);
  const size_t toc_at = toc_position(doc);
  for (size_t i = 0; i <= doc.blocks.size(); ++i) {
    if (toc && i == toc_at) {
      os << "Contents:\n\n";
      for (const DocBlock& h : doc.blocks)
        if (h.kind == DocBlock::Heading && h.level == 2) os << "- [" << h.text << "](#" << md_anchor(h.text) << ")\n";
      os << "\n";
    }
    if (i == doc.blocks.size()) break;
    const DocBlock& b = doc.blocks[i];
    switch (b.kind) {
      case DocBlock::Heading:
        os << std::string(static_cast<size_t>(b.level), '#') << " " << b.text << "\n\n";
        break;
      case DocBlock::Para:
        os << (b.strong ? "**" + b.text + "**" : b.text) << "\n\n";
        break;
      case DocBlock::List:
        if (!b.text.empty()) os << b.text << ":\n\n";
        for (const auto& item : b.items) os << "- " << item << "\n";
        os << "\n";
        break;
      case DocBlock::Figure:
        os << "![" << b.text << "](" << b.file << ")\n\n";
        break;
      case DocBlock::Links:
        os << (b.text.empty() ? "" : b.text + " ") << md_links(b.links) << "\n\n";
        break;
      case DocBlock::Table: {
        const DocTable& t = b.table;
        if (!b.text.empty()) os << b.text << ":\n\n";
        os << "|";
        for (const auto& h : t.header) os << " " << md_cell(h) << " |";
        os << "\n|";
        for (size_t k = 0; k < t.header.size(); ++k) os << (t.row_headers && k > 0 ? "---:|" : "---|");
        os << "\n";
        for (const auto& row : t.rows) {
          os << "|";
          for (const auto& c : row) os << " " << (c.href.empty() ? md_cell(c.text) : "[" + md_cell(c.text) + "](" + c.href + ")") << " |";
          os << "\n";
        }
        os << "\n";
        break;
      }
    }
  }
  if (!doc.footer.empty()) {
    os << "## " << doc.footer_title << "\n\n";
    for (const auto& line : doc.footer) os << "- " << line << "\n";
  }
  return os.str();
}

namespace {

const char* const kCss = R"(body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1280px; padding: 0 1em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.25em; margin-top: 1.8em; border-bottom: 1px solid #ccc; } h3 { font-size: 1.05em; }
table { border-collapse: collapse; margin: 0.5em 0 1.2em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; text-align: left; vertical-align: top; }
thead th { background: #f0f0f0; text-align: center; }
table.num td { text-align: right; } table.num tbody th { text-align: left; }
.wide { overflow-x: auto; }
td.good, th.good { background: #c8ecc8; } td.warn, th.warn { background: #fde5a6; } td.bad, th.bad { background: #f6b8b8; }
td.c-ok { background: #c8e6c9; } td.c-regime { background: #fff59d; }
td.c-unphysical { background: #ffcc80; } td.c-clamped { background: #ce93d8; }
td.c-diverged { background: #ef9a9a; } td.c-failed { background: #bdbdbd; } td.c-contact_lost { background: #90caf9; }
td.v-1pct { background: #a8dba8; } td.v-regime { background: #d4eed4; } td.v-10pct { background: #fde5a6; }
td.v-beyond { background: #ffb870; } td.v-wrong { background: #f08c8c; } td.v-failed { background: #bdbdbd; }
table.matrix td { text-align: left; } table.matrix td a { color: #111; }
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; }
details { margin: 0.4em 0; } summary { cursor: pointer; font-weight: bold; }
nav.top { font-size: 0.9em; margin-bottom: 0.5em; } nav.toc { font-size: 0.9em; border: 1px solid #ddd; padding: 0.3em 1em; display: inline-block; }
footer { margin-top: 2em; font-size: 0.85em; color: #555; border-top: 1px solid #ccc; }
.note { color: #555; font-style: italic; }
.verdict { background: #eef4fb; border-left: 4px solid #0072b2; padding: 0.4em 0.8em; margin: 0.3em 0; }
.unconverged { background: #fde5a6; padding: 0.4em 0.6em; border-left: 4px solid #d9a400; }
)";

std::string html_links(const std::vector<DocLink>& links) {
  std::string s;
  for (const DocLink& l : links)
    s += (s.empty() ? "" : " · ") + ("<a href=\"" + markup_escape(l.href) + "\">" + markup_escape(l.text) + "</a>");
  return s;
}

std::string html_table(const DocTable& t) {
  std::string css = t.css;
  if (t.row_headers) css += css.empty() ? "num" : " num";
  std::string s = "<div class=\"wide\">\n<table" + (css.empty() ? std::string() : " class=\"" + markup_escape(css) + "\"") +
                  ">\n";
  if (!t.header.empty()) {
    s += "<thead><tr>";
    for (const auto& h : t.header) s += "<th>" + markup_escape(h) + "</th>";
    s += "</tr></thead>\n";
  }
  s += "<tbody>\n";
  for (const auto& row : t.rows) {
    s += "<tr>";
    for (size_t i = 0; i < row.size(); ++i) {
      const std::string tag = t.row_headers && i == 0 ? "th" : "td";
      const std::string text = row[i].href.empty() ? markup_escape(row[i].text)
                                                   : "<a href=\"" + markup_escape(row[i].href) + "\">" + markup_escape(row[i].text) + "</a>";
      s += "<" + tag + (row[i].css.empty() ? std::string() : " class=\"" + markup_escape(row[i].css) + "\"") + ">" + text +
           "</" + tag + ">";
    }
    s += "</tr>\n";
  }
  return s + "</tbody>\n</table>\n</div>\n";
}

}  // namespace

std::string render_document_html(const Document& doc) {
  std::ostringstream os;
  os << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>"
     << markup_escape(doc.title) << "</title>\n<style>\n" << kCss << "</style>\n</head>\n<body>\n";
  if (!doc.top_links.empty()) os << "<nav class=\"top\">" << html_links(doc.top_links) << "</nav>\n";
  const bool toc = wants_toc(doc);
  const size_t toc_at = toc_position(doc);
  int section = 0;
  for (size_t i = 0; i <= doc.blocks.size(); ++i) {
    if (toc && i == toc_at) {
      os << "<nav class=\"toc\"><strong>Contents</strong>\n<ul>\n";
      int k = 0;
      for (const DocBlock& h : doc.blocks)
        if (h.kind == DocBlock::Heading) {
          ++k;
          if (h.level == 2) os << "<li><a href=\"#sec-" << k << "\">" << markup_escape(h.text) << "</a></li>\n";
        }
      os << "</ul>\n</nav>\n";
    }
    if (i == doc.blocks.size()) break;
    const DocBlock& b = doc.blocks[i];
    switch (b.kind) {
      case DocBlock::Heading: {
        const std::string tag = "h" + std::to_string(b.level < 1 ? 1 : b.level > 4 ? 4 : b.level);
        os << "<" << tag << " id=\"sec-" << ++section << "\">" << markup_escape(b.text) << "</" << tag << ">\n";
        break;
      }
      case DocBlock::Para: {
        const std::string text = b.strong ? "<strong>" + markup_escape(b.text) + "</strong>" : markup_escape(b.text);
        os << "<p" << (b.css.empty() ? std::string() : " class=\"" + markup_escape(b.css) + "\"") << ">" << text << "</p>\n";
        break;
      }
      case DocBlock::List: {
        std::string items;
        for (const auto& item : b.items) items += "<li>" + markup_escape(item) + "</li>\n";
        if (b.folded)
          os << "<details><summary>" << markup_escape(b.text) << "</summary>\n<ul>\n" << items << "</ul>\n</details>\n";
        else
          os << (b.text.empty() ? "" : "<p>" + markup_escape(b.text) + ":</p>\n") << "<ul>\n" << items << "</ul>\n";
        break;
      }
      case DocBlock::Figure:
        os << "<figure><img src=\"" << markup_escape(b.file) << "\" alt=\"" << markup_escape(b.text) << "\"><figcaption>"
           << markup_escape(b.text) << "</figcaption></figure>\n";
        break;
      case DocBlock::Links:
        os << "<p>" << (b.text.empty() ? "" : markup_escape(b.text) + " ") << html_links(b.links) << "</p>\n";
        break;
      case DocBlock::Table:
        if (b.folded)
          os << "<details" << (b.open ? " open" : "") << "><summary>" << markup_escape(b.text) << "</summary>\n"
             << html_table(b.table) << "</details>\n";
        else
          os << (b.text.empty() ? "" : "<p>" + markup_escape(b.text) + ":</p>\n") << html_table(b.table);
        break;
    }
  }
  if (!doc.footer.empty()) {
    os << "<footer>\n<p>";
    for (size_t i = 0; i < doc.footer.size(); ++i) os << (i ? "<br>\n" : "") << markup_escape(doc.footer[i]);
    os << "</p>\n</footer>\n";
  }
  os << "</body>\n</html>\n";
  return os.str();
}

}  // namespace tippe
