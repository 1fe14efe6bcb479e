#pragma once
// INI configuration in MRPT's syntax: [Section], key = value, comments after
// ';', '#' or '//', matrices as "[a b; c d]". Our own parser so that every
// error names file, line, section, key and value (and the core library stays
// free of MRPT). Each component reads its own [Section].
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "gssm/io/number_text.h"  // formatDouble, which the INI writer uses

namespace gssm::io {

class IniDocument {
 public:
  /// Parses text; `source` names it in errors (a file path).
  static IniDocument parse(const std::string& text, const std::string& source = "<ini>");
  /// Reads and parses a file; throws InputError if it cannot be read.
  static IniDocument load(const std::string& path);

  bool hasSection(const std::string& section) const;
  bool has(const std::string& section, const std::string& key) const;

  /// Typed getters; each throws InputError naming source:line, [section],
  /// key and value when the value does not parse, or when a required key is
  /// missing.
  std::string getString(const std::string& section, const std::string& key) const;
  std::string getString(const std::string& section, const std::string& key,
                        const std::string& fallback) const;
  double getDouble(const std::string& section, const std::string& key) const;
  double getDouble(const std::string& section, const std::string& key, double fallback) const;
  long long getInt(const std::string& section, const std::string& key) const;
  long long getInt(const std::string& section, const std::string& key, long long fallback) const;
  bool getBool(const std::string& section, const std::string& key, bool fallback) const;
  /// "[a b c]" or "a b c" (commas allowed). `size` < 0 accepts any length.
  Eigen::VectorXd getVector(const std::string& section, const std::string& key,
                            Eigen::Index size = -1) const;
  /// "[a b; c d]"; a vector of n entries with rows = cols = n is read as a diagonal.
  Eigen::MatrixXd getMatrix(const std::string& section, const std::string& key,
                            Eigen::Index rows = -1, Eigen::Index cols = -1) const;

  /// Sets (or replaces) a value; sections and keys keep insertion order.
  void set(const std::string& section, const std::string& key, const std::string& value);
  void set(const std::string& section, const std::string& key, double value);
  void set(const std::string& section, const std::string& key, const Eigen::MatrixXd& value);
  void setComment(const std::string& section, const std::string& comment);

  /// Serializes (deterministic: round-trip number formatting).
  std::string toString() const;
  void save(const std::string& path) const;

  /// Whether the document has a section `[prefix.S]` (one reader's own
  /// values of another section's keys, e.g. [batch.model]).
  bool hasOverrides(const std::string& prefix) const;
  /// A copy with every key of each `[prefix.S]` set in [S] (its line
  /// kept, so that an error about it points there): how the reader named
  /// `prefix` sees the document. InputError naming the line of a
  /// `[prefix.S]` whose [S] the document does not have (a misspelt name
  /// would otherwise change nothing, silently).
  IniDocument overriddenBy(const std::string& prefix) const;

  /// Throws InputError if a section has a key not in `allowed` (catches typos).
  void requireOnlyKeys(const std::string& section, const std::vector<std::string>& allowed) const;

  const std::string& source() const { return source_; }
  /// The file line of [section] key (0: absent, or set in memory).
  int lineOf(const std::string& section, const std::string& key) const;
  /// The line of the section's last key (or of its header); 0 when absent.
  int lastLineOf(const std::string& section) const;
  /// "file:line: [section] key" where the key is, "file: [section] key" where it is not.
  std::string where(const std::string& section, const std::string& key) const;

 private:
  struct Entry {
    std::string key, value;
    int line = 0;
  };
  struct Section {
    std::string name, comment;
    std::vector<Entry> entries;
    int line = 0;
  };
  Section& sectionFor(const std::string& section);
  const Entry* find(const std::string& section, const std::string& key) const;
  const Entry& require(const std::string& section, const std::string& key) const;
  [[noreturn]] void fail(const std::string& section, const Entry& e,
                         const std::string& expected) const;

  std::string source_;
  std::vector<Section> sections_;
};


}  // namespace gssm::io
