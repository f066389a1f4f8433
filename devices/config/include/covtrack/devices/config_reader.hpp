#pragma once
// Validated reading of one TOML table against a declared schema. Every problem becomes
// one error with file:line:column and the full key path; reading goes on so that a user
// sees all of a config's mistakes at once. The same schema prints config/schema.md.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack {

enum class ValueType { Integer, Float, String, Boolean, FloatArray, StringArray, Table, TableArray };
const char* to_string(ValueType type);

struct KeySpec {
  std::string_view key;
  ValueType type;
  std::string_view unit;           // "m", "Hz", "" ...
  std::string_view default_value;  // empty: required
  std::string_view doc;
  double min = -std::numeric_limits<double>::infinity();  // inclusive, numbers and array items
  double max = std::numeric_limits<double>::infinity();
  std::size_t array_size = 0;  // FloatArray: exact item count, 0 = any
};

struct TableSpec {
  std::string_view name;  // for the schema document, e.g. "devices.<name> (type = \"sim\")"
  std::string_view reader;  // who reads it: "daemon", "sim driver", ...
  std::vector<KeySpec> keys;
};

// A check of something a config value names outside the config (a file, a folder; never
// a device, which may be plugged in later). Only `covtrackd --check` runs these: at start
// a file that is missing may appear later, and its driver retries it with back-off.
using ResourceCheck = std::function<Result<void>()>;

class ConfigErrors {
 public:
  void add(const std::string& file, const toml::source_region& where,
           const std::string& key_path, const std::string& message);
  bool empty() const { return errors_.empty(); }
  const std::vector<std::string>& list() const { return errors_; }
  std::string joined() const;

  void add_resource_check(const std::string& file, const toml::source_region& where,
                          const std::string& key_path, ResourceCheck check);
  // Runs the resource checks recorded so far; each failure becomes an error at its key.
  void run_resource_checks();

 private:
  struct PendingCheck {
    std::string file;
    toml::source_region where;
    std::string key_path;
    ResourceCheck check;
  };
  std::vector<std::string> errors_;
  std::vector<PendingCheck> checks_;
};

class TableReader {
 public:
  // Reports every key of `table` that `spec` does not declare.
  TableReader(const toml::table& table, std::string key_path, const TableSpec& spec,
              std::string file, ConfigErrors& errors);

  bool has(std::string_view key) const;
  // Each getter checks type and range; on a problem it records an error and returns
  // the fallback so reading can go on. A missing required key is an error too.
  std::int64_t integer(std::string_view key, std::int64_t fallback = 0);
  double number(std::string_view key, double fallback = 0);  // integers accepted
  std::string string(std::string_view key, std::string fallback = {});
  // One of the allowed words.
  std::string choice(std::string_view key, const std::vector<std::string_view>& allowed,
                     std::string fallback = {});
  bool boolean(std::string_view key, bool fallback = false);
  std::vector<double> numbers(std::string_view key);
  // A 3-number key (its spec has array_size 3); the fallback when absent or invalid.
  Vec3 vec3(std::string_view key, const Vec3& fallback = Vec3::Zero());
  std::vector<std::string> strings(std::string_view key);
  // A sub-table, or nullptr if absent (an error if required or of the wrong type).
  const toml::table* table(std::string_view key);
  // An array of tables ([[key]] in TOML): each element checked to be a table.
  std::vector<const toml::table*> tables(std::string_view key);

  // Records `check` of the resource `key` names (see ResourceCheck); nothing if absent.
  void resource(std::string_view key, ResourceCheck check);
  // Records a problem that only the caller can judge (e.g. two keys that conflict).
  void error(std::string_view key, const std::string& message);
  std::string path(std::string_view key) const;
  const std::string& file() const { return file_; }
  ConfigErrors& errors() { return errors_; }

 private:
  const KeySpec* spec_of(std::string_view key);
  const toml::node* present(std::string_view key, const KeySpec** spec);
  const toml::node* typed(std::string_view key, const KeySpec** spec);
  bool in_range(const KeySpec& spec, double value, std::string_view key, const toml::node& node);

  const toml::table& table_;
  std::string key_path_;
  const TableSpec& spec_;
  std::string file_;
  ConfigErrors& errors_;
};

// Config files are small: a larger one (or an endless pipe) is refused, not read into memory.
inline constexpr std::size_t kMaxConfigBytes = 4 << 20;
// The whole text of a config file (a regular file or a pipe), or an error naming it. Bulk
// data a config names (a scene's transform tables) passes a larger bound.
Result<std::string> read_config_text(const std::string& path, std::size_t max_bytes = kMaxConfigBytes);
// Parsed TOML, or one error "source:line:column: TOML syntax error: ...".
Result<toml::table> parse_toml(std::string_view text, const std::string& source_name);

// Markdown for config/schema.md: one section per table, one row per key.
std::string schema_markdown(const std::vector<const TableSpec*>& tables);

}  // namespace covtrack
