#pragma once
// A small command-line parser shared by the apps: "--name value" options and
// "--flag" switches, each declared with its help text. Unknown or malformed
// options give a one-line error naming them.
#include <charconv>
#include <cstdlib>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <malloc.h>  // mallopt: glibc (Debian, the platform the project targets)

namespace gssm::apps {

class CommandLine {
 public:
  CommandLine(std::string program, std::string summary)
      : program_(std::move(program)), summary_(std::move(summary)) {}

  void option(const std::string& name, const std::string& value_name, const std::string& help,
              const std::string& fallback = "") {
    specs_.push_back({name, value_name, help, fallback, false});
  }
  void flag(const std::string& name, const std::string& help) {
    specs_.push_back({name, "", help, "", true});
  }

  /// Parses argv; prints help and exits 0 on --help; throws std::invalid_argument.
  void parse(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--help" || arg == "-h") {
        std::cout << help();
        std::exit(0);
      }
      const Spec* s = find(arg);
      if (!s) throw std::invalid_argument("unknown option '" + arg + "' (see --help)");
      if (s->is_flag) {
        values_[s->name] = "1";
        continue;
      }
      if (i + 1 >= argc) throw std::invalid_argument("option " + arg + " needs a value <" + s->value_name + ">");
      values_[s->name] = argv[++i];
    }
  }

  bool given(const std::string& name) const { return values_.count(name) != 0; }
  std::string get(const std::string& name) const {
    auto it = values_.find(name);
    if (it != values_.end()) return it->second;
    for (const auto& s : specs_)
      if (s.name == name) return s.fallback;
    return "";
  }
  std::string require(const std::string& name) const {
    const std::string v = get(name);
    if (v.empty()) throw std::invalid_argument("missing required option --" + name + " (see --help)");
    return v;
  }
  long long getInt(const std::string& name, long long lo, long long hi) const {
    const std::string v = get(name);
    char* end = nullptr;
    const long long x = std::strtoll(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0' || x < lo || x > hi)
      throw std::invalid_argument("option --" + name + " = '" + v + "': expected an integer in [" +
                                  std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return x;
  }

  double getDouble(const std::string& name, double lo, double hi) const {
    const std::string v = get(name);
    double x = 0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
    if (v.empty() || ec != std::errc() || end != v.data() + v.size() || !(x >= lo && x <= hi))
      throw std::invalid_argument("option --" + name + " = '" + v + "': expected a number in [" + std::to_string(lo) +
                                  ", " + std::to_string(hi) + "]");
    return x;
  }

  std::string help() const {
    std::string out = "usage: " + program_ + " [options]\n\n" + summary_ + "\n\noptions:\n";
    for (const auto& s : specs_) {
      std::string left = "  --" + s.name + (s.is_flag ? "" : " <" + s.value_name + ">");
      if (left.size() < 30) left.resize(30, ' ');
      out += left + " " + s.help;
      if (!s.fallback.empty()) out += " (default: " + s.fallback + ")";
      out += "\n";
    }
    out += "  --help                       show this help\n";
    return out;
  }

 private:
  struct Spec {
    std::string name, value_name, help, fallback;
    bool is_flag;
  };
  const Spec* find(const std::string& arg) const {
    if (arg.rfind("--", 0) != 0) return nullptr;
    for (const auto& s : specs_)
      if (arg.substr(2) == s.name) return &s;
    return nullptr;
  }
  std::string program_, summary_;
  std::vector<Spec> specs_;
  std::map<std::string, std::string> values_;
};

/// Runs `body`, turning exceptions into a one-line error and exit code.
// The apps allocate and free the same large blocks again and again (a
// batch solve's 24 MB information matrix per iteration, every method's
// rows): glibc's default returns freed memory to the system at once and the
// next allocation pays its page faults again (sys time 0.5 s of 9 on the
// UWB log). Keep up to 1 GiB of it for reuse, and take blocks up to 32 MiB
// (glibc's largest mapping threshold) from the heap, where they are reused.
inline void keepFreedMemory() {
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TOP_PAD, 64 << 20);
}

template <class Fn>
int runApp(const char* program, Fn body) {
  keepFreedMemory();
  try {
    return body();
  } catch (const std::invalid_argument& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace gssm::apps
