// Checks of a published HTML page: its local links and resources read from the file, and its load in headless Chromium over the DevTools protocol (failed loads, script errors, undecodable images).
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace page_check {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// The page's own text: every src/href/data attribute and every id, by a small tag scanner (the
// pages are the harness's own output, so a full HTML5 parser would buy nothing here).

struct Attribute {
  std::string tag, name, value;
};

struct ScannedPage {
  std::vector<Attribute> links;  // src, href and data attributes, entities decoded
  std::set<std::string> anchors;  // id attributes, and name attributes of <a>
};

inline std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The character references the harness writes (&amp; &lt; &gt; &quot; &#39; and numeric ones
// below 128); any other is kept as written.
inline std::string decode_entities(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '&') {
      out += s[i];
      continue;
    }
    const size_t semi = s.find(';', i);
    if (semi == std::string::npos || semi - i > 10) {
      out += s[i];
      continue;
    }
    const std::string name = s.substr(i + 1, semi - i - 1);
    static const std::map<std::string, char> named = {{"amp", '&'}, {"lt", '<'}, {"gt", '>'}, {"quot", '"'}, {"apos", '\''}};
    long code = -1;
    if (named.count(name)) {
      code = named.at(name);
    } else if (name.size() > 1 && name[0] == '#') {
      const bool hex = name[1] == 'x' || name[1] == 'X';
      char* end = nullptr;
      const std::string digits = name.substr(hex ? 2 : 1);
      code = std::strtol(digits.c_str(), &end, hex ? 16 : 10);
      if (digits.empty() || *end != '\0' || code <= 0 || code >= 128) code = -1;
    }
    if (code < 0) {
      out += s[i];
      continue;
    }
    out += static_cast<char>(code);
    i = semi;
  }
  return out;
}

inline ScannedPage scan_html(const std::string& html) {
  ScannedPage page;
  size_t i = 0;
  const size_t n = html.size();
  auto skip_space = [&] {
    while (i < n && std::isspace(static_cast<unsigned char>(html[i]))) ++i;
  };
  while ((i = html.find('<', i)) != std::string::npos) {
    if (html.compare(i, 4, "<!--") == 0) {
      const size_t end = html.find("-->", i + 4);
      i = end == std::string::npos ? n : end + 3;
      continue;
    }
    ++i;
    if (i >= n || !std::isalpha(static_cast<unsigned char>(html[i]))) continue;  // </x>, <!DOCTYPE>, text '<'
    size_t start = i;
    while (i < n && (std::isalnum(static_cast<unsigned char>(html[i])) || html[i] == '-')) ++i;
    const std::string tag = lower(html.substr(start, i - start));
    while (true) {
      skip_space();
      if (i >= n || html[i] == '>') break;
      if (html[i] == '/') {
        ++i;
        continue;
      }
      start = i;
      while (i < n && !std::isspace(static_cast<unsigned char>(html[i])) && html[i] != '=' && html[i] != '>' && html[i] != '/') ++i;
      const std::string name = lower(html.substr(start, i - start));
      if (name.empty()) {  // a stray character: step over it
        ++i;
        continue;
      }
      skip_space();
      std::string value;
      if (i < n && html[i] == '=') {
        ++i;
        skip_space();
        if (i < n && (html[i] == '"' || html[i] == '\'')) {
          const char q = html[i++];
          const size_t end = html.find(q, i);
          value = html.substr(i, end == std::string::npos ? std::string::npos : end - i);
          i = end == std::string::npos ? n : end + 1;
        } else {
          start = i;
          while (i < n && !std::isspace(static_cast<unsigned char>(html[i])) && html[i] != '>') ++i;
          value = html.substr(start, i - start);
        }
      }
      value = decode_entities(value);
      if (name == "src" || name == "href" || name == "data") page.links.push_back({tag, name, value});
      if (name == "id" || (tag == "a" && name == "name")) page.anchors.insert(value);
    }
    if (i < n) ++i;  // the '>'
    // A script's or a style's text is not markup.
    if (tag == "script" || tag == "style") {
      const std::string lowered_rest = lower(html.substr(i, std::min<size_t>(n - i, 1 << 22)));
      const size_t end = lowered_rest.find("</" + tag);
      i = end == std::string::npos ? n : i + end;
    }
  }
  return page;
}

inline std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::string percent_decode(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

inline bool has_scheme(const std::string& v) {
  if (v.empty() || !std::isalpha(static_cast<unsigned char>(v[0]))) return false;
  for (char c : v) {
    if (c == ':') return true;
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '+' && c != '-' && c != '.') return false;
  }
  return false;
}

// Every local reference of the page that leads nowhere: a relative src/href/data naming a file
// that does not exist, a #fragment naming no id (in the page, or in the local page linked), an
// absolute path (a published page moves with its folder), and a resource loaded from the network
// (a published page must display offline; a plain <a href> to a web page is allowed).
inline std::vector<std::string> check_local_links(const fs::path& page) {
  std::vector<std::string> problems;
  const ScannedPage scanned = scan_html(read_text(page));
  std::map<fs::path, std::set<std::string>> anchors_of;  // linked local pages, scanned once
  for (const Attribute& a : scanned.links) {
    const std::string where = "<" + a.tag + " " + a.name + "=\"" + a.value + "\">";
    const bool is_resource = !(a.name == "href" && (a.tag == "a" || a.tag == "area"));
    std::string v = a.value;
    while (!v.empty() && std::isspace(static_cast<unsigned char>(v.front()))) v.erase(v.begin());
    while (!v.empty() && std::isspace(static_cast<unsigned char>(v.back()))) v.pop_back();
    if (v.empty()) {
      if (is_resource) problems.push_back(where + ": an empty resource address");
      continue;
    }
    if (v.rfind("//", 0) == 0 || has_scheme(v)) {
      const std::string scheme = v.rfind("//", 0) == 0 ? "" : lower(v.substr(0, v.find(':')));
      if (scheme == "file") problems.push_back(where + ": a file: address (a path of the machine that wrote it)");
      else if (is_resource && scheme != "data") problems.push_back(where + ": a resource from the network (the page must display offline)");
      continue;
    }
    std::string fragment;
    if (const size_t hash = v.find('#'); hash != std::string::npos) {
      fragment = percent_decode(v.substr(hash + 1));
      v.erase(hash);
    }
    if (const size_t q = v.find('?'); q != std::string::npos) v.erase(q);
    if (v.empty()) {  // "#id" in the page itself
      if (!fragment.empty() && !scanned.anchors.count(fragment)) problems.push_back(where + ": no element with id \"" + fragment + "\" in the page");
      continue;
    }
    if (v[0] == '/') {
      problems.push_back(where + ": an absolute path (a published page must link relative to its folder)");
      continue;
    }
    fs::path target = page.parent_path() / percent_decode(v);
    if (fs::is_directory(target)) target /= "index.html";
    if (!fs::is_regular_file(target)) {
      problems.push_back(where + ": " + target.lexically_normal().string() + " does not exist");
      continue;
    }
    if (!fragment.empty() && (target.extension() == ".html" || target.extension() == ".htm")) {
      auto it = anchors_of.find(target);
      if (it == anchors_of.end()) it = anchors_of.emplace(target, scan_html(read_text(target)).anchors).first;
      if (!it->second.count(fragment)) problems.push_back(where + ": no element with id \"" + fragment + "\" in " + target.lexically_normal().string());
    }
  }
  return problems;
}

// ---------------------------------------------------------------------------------------------
// Headless Chromium driven over --remote-debugging-pipe: the DevTools protocol as JSON messages
// ended by NUL, written to the browser's fd 3 and read from its fd 4. The protocol, unlike the
// browser's log (--enable-logging), reports each failed load with its address and each uncaught
// exception, and lets the test ask the page whether its images decoded.

// The executable: $TIPPE_CHROMIUM, else `chromium` or `chromium-browser` on PATH; empty if none
// (or if $TIPPE_CHROMIUM names no executable).
inline std::string find_chromium() {
  if (const char* e = std::getenv("TIPPE_CHROMIUM"); e && *e) return ::access(e, X_OK) == 0 ? e : "";
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  std::vector<std::string> all;
  while (std::getline(dirs, dir, ':')) all.push_back(dir.empty() ? "." : dir);
  for (const char* name : {"chromium", "chromium-browser"})
    for (const std::string& d : all)
      if (::access((fs::path(d) / name).c_str(), X_OK) == 0) return (fs::path(d) / name).string();
  return "";
}

// A file: URL for an absolute path, every byte outside the unreserved set and '/' escaped.
inline std::string file_url(const fs::path& absolute) {
  static const char* hex = "0123456789ABCDEF";
  std::string url = "file://";
  for (unsigned char c : absolute.string()) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~') {
      url += static_cast<char>(c);
    } else {
      url += '%';
      url += hex[c >> 4];
      url += hex[c & 15];
    }
  }
  return url;
}

class Chromium {
 public:
  // Starts the browser with a fresh profile in `work_dir` (its log goes to work_dir/chromium.log).
  // No network: background services off, every host name unresolvable and every proxy request
  // sent to a closed local port, so a page that reaches out fails to load instead.
  Chromium(const std::string& executable, const fs::path& work_dir) : work_dir_(work_dir) {
    fs::create_directories(work_dir / "profile");
    int to_browser[2], from_browser[2];
    if (::pipe2(to_browser, O_CLOEXEC) != 0 || ::pipe2(from_browser, O_CLOEXEC) != 0) throw std::runtime_error("pipe2 failed");
    const std::vector<std::string> argv = {
        executable, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
        "--disable-background-networking", "--disable-component-update", "--disable-default-apps",
        "--disable-extensions", "--disable-sync", "--no-first-run", "--no-default-browser-check",
        "--mute-audio", "--proxy-server=127.0.0.1:9", "--host-resolver-rules=MAP * ~NOTFOUND",
        "--remote-debugging-pipe", "--user-data-dir=" + (work_dir / "profile").string(), "about:blank"};
    const std::string log = (work_dir / "chromium.log").string();
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      ::setpgid(0, 0);  // its own process group: the renderer and GPU processes go with it
      // Out of the way of 3 and 4 first, then onto them (dup2 clears close-on-exec).
      const int in = ::fcntl(to_browser[0], F_DUPFD, 10), out = ::fcntl(from_browser[1], F_DUPFD, 10);
      ::dup2(in, 3);
      ::dup2(out, 4);
      const int logfd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
      ::dup2(logfd, 1);
      ::dup2(logfd, 2);
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
    ::setpgid(pid_, pid_);
    ::close(to_browser[0]);
    ::close(from_browser[1]);
    write_fd_ = to_browser[1];
    read_fd_ = from_browser[0];
    ::signal(SIGPIPE, SIG_IGN);  // a browser that died is reported by the read, not by a signal
    try {
      const auto target = call("Target.createTarget", {{"url", "about:blank"}});
      session_ = call("Target.attachToTarget", {{"targetId", target.at("targetId")}, {"flatten", true}}).at("sessionId").get<std::string>();
      for (const char* domain : {"Runtime.enable", "Log.enable", "Network.enable", "Page.enable"}) call(domain, json::object(), true);
    } catch (...) {
      // No destructor runs for a constructor that throws: the browser goes here.
      ::close(write_fd_);
      ::close(read_fd_);
      ::kill(-pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
      throw;
    }
  }

  Chromium(const Chromium&) = delete;
  Chromium& operator=(const Chromium&) = delete;

  ~Chromium() {
    try {
      call("Browser.close", json::object(), false, 5.0);
    } catch (...) {
    }
    ::close(write_fd_);
    ::close(read_fd_);
    // Browser.close ends it; a browser still there after 10 s is killed with its children.
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    int status = 0;
    while (::waitpid(pid_, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > end) {
        ::kill(-pid_, SIGKILL);
        ::waitpid(pid_, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ::kill(-pid_, SIGKILL);  // children left behind by a browser that exited (none expected)
  }

  // Loads the page and returns what went wrong: every failed load (with its address), every
  // uncaught exception, every console error, every request that left the machine's files, and
  // every <img> that did not decode (a file that exists but is no image).
  std::vector<std::string> load(const fs::path& page, double timeout_seconds = 60.0) {
    problems_.clear();
    requests_.clear();
    const json nav = call("Page.navigate", {{"url", file_url(fs::absolute(page))}}, true, timeout_seconds);
    if (nav.contains("errorText")) problems_.push_back("navigation failed: " + nav.at("errorText").get<std::string>());
    else wait_for("Page.loadEventFired", timeout_seconds);
    // Scripts run by timers right after the load get 100 ms to fail; the answer also orders
    // every event of the load before it.
    call("Runtime.evaluate", {{"expression", "new Promise(r => setTimeout(r, 100))"}, {"awaitPromise", true}}, true, timeout_seconds);
    const json broken = call("Runtime.evaluate",
                             {{"expression",
                               "Array.from(document.images).filter(i => !i.complete || i.naturalWidth === 0)"
                               ".map(i => i.getAttribute('src'))"},
                              {"returnByValue", true}},
                             true, timeout_seconds);
    for (const auto& src : broken.at("result").value("value", json::array()))
      problems_.push_back("image not displayed (missing or not decodable): " + (src.is_string() ? src.get<std::string>() : src.dump()));
    return problems_;
  }

  // The value of a JavaScript expression on the page loaded last (a Promise is awaited), as JSON.
  nlohmann::json evaluate(const std::string& expression, double timeout_seconds = 30.0) {
    const nlohmann::json r = call("Runtime.evaluate", {{"expression", expression}, {"returnByValue", true}, {"awaitPromise", true}},
                                  true, timeout_seconds);
    if (r.contains("exceptionDetails")) throw std::runtime_error("evaluate: " + r.at("exceptionDetails").dump());
    return r.at("result").value("value", nlohmann::json());
  }

 private:
  using json = nlohmann::json;

  json call(const std::string& method, const json& params, bool in_session = false, double timeout_seconds = 30.0) {
    const int id = ++last_id_;
    json m = {{"id", id}, {"method", method}, {"params", params}};
    if (in_session) m["sessionId"] = session_;
    const std::string text = m.dump() + '\0';
    for (size_t done = 0; done < text.size();) {
      const ssize_t w = ::write(write_fd_, text.data() + done, text.size() - done);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) throw std::runtime_error("chromium closed its DevTools pipe" + log_tail());
      done += static_cast<size_t>(w);
    }
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(timeout_seconds));
    while (true) {
      const json r = next_message(deadline, method);
      if (r.value("id", -1) == id) {
        if (r.contains("error")) throw std::runtime_error(method + ": " + r.at("error").dump());
        return r.value("result", json::object());
      }
      note_event(r);
    }
  }

  void wait_for(const std::string& event, double timeout_seconds) {
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(timeout_seconds));
    while (true) {
      const json e = next_message(deadline, event);
      note_event(e);
      if (e.value("method", "") == event) return;
    }
  }

  json next_message(std::chrono::steady_clock::time_point deadline, const std::string& waiting_for) {
    while (true) {
      if (const size_t end = buffer_.find('\0'); end != std::string::npos) {
        const std::string text = buffer_.substr(0, end);
        buffer_.erase(0, end + 1);
        return json::parse(text);
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
      if (left <= 0) throw std::runtime_error("chromium: no answer to " + waiting_for + " in time" + log_tail());
      pollfd p{read_fd_, POLLIN, 0};
      const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 1000)));
      if (ready < 0 && errno == EINTR) continue;
      if (ready <= 0) continue;
      char chunk[65536];
      const ssize_t r = ::read(read_fd_, chunk, sizeof chunk);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) throw std::runtime_error("chromium closed its DevTools pipe" + log_tail());
      buffer_.append(chunk, static_cast<size_t>(r));
    }
  }

  // The end of the browser's own log, for a failure message (the log goes with the work directory).
  std::string log_tail() const {
    const std::string log = read_text(work_dir_ / "chromium.log");
    return "; the end of its log:\n" + (log.size() > 3000 ? log.substr(log.size() - 3000) : log);
  }

  void note_event(const json& e) {
    const std::string method = e.value("method", "");
    if (method.empty() || !e.contains("params")) return;
    const json& p = e.at("params");
    if (method == "Network.requestWillBeSent") {
      const std::string url = p.at("request").value("url", "");
      requests_[p.value("requestId", "")] = url;
      const std::string scheme = lower(url.substr(0, url.find(':')));
      if (scheme != "file" && scheme != "data" && scheme != "about") problems_.push_back("request leaves the page's files: " + url);
    } else if (method == "Network.loadingFailed") {
      const std::string id = p.value("requestId", "");
      problems_.push_back("failed to load " + (requests_.count(id) ? requests_.at(id) : "request " + id) + ": " + p.value("errorText", "") +
                          (p.value("canceled", false) ? " (canceled)" : ""));
    } else if (method == "Runtime.exceptionThrown") {
      const json& d = p.at("exceptionDetails");
      std::string what = d.value("text", "exception");
      if (d.contains("exception")) what += " " + d.at("exception").value("description", d.at("exception").value("value", json()).dump());
      problems_.push_back("script error: " + what + " at " + d.value("url", "?") + ":" + std::to_string(d.value("lineNumber", 0) + 1));
    } else if (method == "Runtime.consoleAPICalled") {
      const std::string type = p.value("type", "");
      if (type == "error" || type == "assert") {
        std::string text;
        for (const json& a : p.value("args", json::array())) text += (text.empty() ? "" : " ") + (a.contains("value") ? a.at("value").dump() : a.value("description", ""));
        problems_.push_back("console." + type + ": " + text);
      }
    } else if (method == "Log.entryAdded") {
      const json& entry = p.at("entry");
      // Network errors arrive as Network.loadingFailed already, with their address.
      if (entry.value("level", "") == "error" && entry.value("source", "") != "network")
        problems_.push_back("browser error (" + entry.value("source", "") + "): " + entry.value("text", "") + " " + entry.value("url", ""));
    }
  }

  fs::path work_dir_;
  pid_t pid_ = -1;
  int write_fd_ = -1, read_fd_ = -1;
  int last_id_ = 0;
  std::string session_;
  std::string buffer_;
  std::vector<std::string> problems_;
  std::map<std::string, std::string> requests_;  // requestId -> address
};

}  // namespace page_check
