// One document model for every report page (headings, paragraphs, lists, tables with a class per cell, figures, links, a table of contents), rendered to Markdown and to one self-contained HTML page.
#pragma once

#include <string>
#include <vector>

#include "harness/io/text.h"

namespace tippe {

// A table cell: its text, an optional CSS class (the page's colours: "good", "warn", "bad", the
// stability classes "c-ok", "c-regime", ..., the verdict classes "v-1pct", ..., "v-failed") and an
// optional link (relative to the page) the text leads to; Markdown shows the text (as a link).
struct DocCell {
  std::string text;
  std::string css;
  std::string href;
  DocCell() = default;
  DocCell(std::string t, std::string c = "", std::string h = "") : text(std::move(t)), css(std::move(c)), href(std::move(h)) {}
  DocCell(const char* t) : text(t) {}
};

struct DocTable {
  std::vector<std::string> header;
  std::vector<std::vector<DocCell>> rows;
  // The first column names the row (a <th>, left-aligned) and the others are numbers
  // (right-aligned); otherwise every cell is text, left-aligned.
  bool row_headers = false;
  std::string css;  // the table's own class ("params", "summary", ...)
};

struct DocLink {
  std::string text, href;  // href relative to the page
};

struct DocBlock {
  enum Kind { Heading, Para, List, Table, Figure, Links } kind = Para;
  int level = 2;         // Heading: 1..3
  std::string text;      // heading, paragraph, figure caption; a table's or list's summary line
  std::string css;       // paragraph class ("verdict", "note", "unconverged")
  bool strong = false;   // a paragraph said in bold
  std::vector<std::string> items;  // List
  DocTable table;                  // Table
  std::string file;                // Figure: image path relative to the page
  std::vector<DocLink> links;      // Links: one line of links
  // Table or List: folded under `text` (HTML <details>), open or not; Markdown shows it whole.
  bool folded = false;
  bool open = false;
};

struct Document {
  std::string title;       // <title>, and the page's first heading when `heading`
  std::vector<DocBlock> blocks;
  std::vector<DocLink> top_links;   // the line above everything: back to the index, the data files
  std::vector<std::string> footer;  // lines of the footer (provenance)
  std::string footer_title = "Provenance";  // its heading in Markdown
  // A table of contents after the first heading's opening paragraphs, of every level-2 heading;
  // made when the page has at least this many of them (0: never).
  int toc_from = 4;

  void heading(int level, const std::string& text);
  void para(const std::string& text, const std::string& css = "", bool strong = false);
  void list(const std::vector<std::string>& items, const std::string& summary = "", bool folded = false);
  void table(const DocTable& t, const std::string& summary = "", bool folded = false, bool open = false);
  void figure(const std::string& file, const std::string& caption);
  void links(const std::vector<DocLink>& links, const std::string& lead = "");
};

// Markdown: headings with '#', tables with pipes (a '|' in a cell escaped), figures as images,
// links as [text](href); the table of contents as a list of links to the headings.
std::string render_document_markdown(const Document& doc);

// One HTML page: inline CSS, no scripts, no network; every text escaped; headings carry ids
// (sec-N, never a name from a record) that the table of contents links to.
std::string render_document_html(const Document& doc);


}  // namespace tippe
