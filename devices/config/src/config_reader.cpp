#include "covtrack/devices/config_reader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "covtrack/devices/file_kind.hpp"

namespace covtrack {

const char* to_string(ValueType type) {
  switch (type) {
    case ValueType::Integer: return "integer";
    case ValueType::Float: return "number";
    case ValueType::String: return "string";
    case ValueType::Boolean: return "boolean";
    case ValueType::FloatArray: return "array of numbers";
    case ValueType::StringArray: return "array of strings";
    case ValueType::Table: return "table";
    case ValueType::TableArray: return "array of tables";
  }
  return "?";
}

namespace {
// A config repeating a mistake thousands of times gets the first ones and a note: its
// report stays readable and its memory bounded.
constexpr std::size_t kMaxErrorsShown = 100;
// Configs and layouts are a few kB; a bigger "config" is something else (a FIFO fed
// forever, a log), and reading it whole would take the daemon's memory.
}  // namespace

void ConfigErrors::add(const std::string& file, const toml::source_region& where,
                       const std::string& key_path, const std::string& message) {
  if (errors_.size() >= kMaxErrorsShown) {
    if (errors_.size() == kMaxErrorsShown)
      errors_.push_back(fmt::format("(only the first {} problems are shown)", kMaxErrorsShown));
    return;
  }
  errors_.push_back(fmt::format("{}:{}:{}: {}: {}", file, where.begin.line, where.begin.column,
                                key_path, message));
}

std::string ConfigErrors::joined() const {
  std::string out;
  for (const auto& e : errors_) out += e + "\n";
  return out;
}

void ConfigErrors::add_resource_check(const std::string& file, const toml::source_region& where,
                                      const std::string& key_path, ResourceCheck check) {
  checks_.push_back({file, where, key_path, std::move(check)});
}

void ConfigErrors::run_resource_checks() {
  for (const PendingCheck& c : checks_) {
    try {  // a check that throws is a failed check at its key, not the end of --check
      if (auto ok = c.check(); !ok) add(c.file, c.where, c.key_path, ok.error().message);
    } catch (const std::exception& e) {
      add(c.file, c.where, c.key_path, fmt::format("cannot be checked: {}", e.what()));
    }
  }
  checks_.clear();
}

TableReader::TableReader(const toml::table& table, std::string key_path, const TableSpec& spec,
                         std::string file, ConfigErrors& errors)
    : table_(table), key_path_(std::move(key_path)), spec_(spec), file_(std::move(file)),
      errors_(errors) {
  for (const auto& [key, node] : table_) {
    if (!spec_of(key.str())) {
      std::string known;
      for (const auto& k : spec_.keys) known += (known.empty() ? "" : ", ") + std::string(k.key);
      errors_.add(file_, key.source(), path(key.str()),
                  fmt::format("unknown key (known keys here: {})", known));
    }
  }
}

std::string TableReader::path(std::string_view key) const {
  return key_path_.empty() ? std::string(key) : key_path_ + "." + std::string(key);
}

const KeySpec* TableReader::spec_of(std::string_view key) {
  auto it = std::find_if(spec_.keys.begin(), spec_.keys.end(),
                         [&](const KeySpec& k) { return k.key == key; });
  return it == spec_.keys.end() ? nullptr : &*it;
}

bool TableReader::has(std::string_view key) const { return table_.contains(key); }

void TableReader::resource(std::string_view key, ResourceCheck check) {
  if (const toml::node* node = table_.get(key))
    errors_.add_resource_check(file_, node->source(), path(key), std::move(check));
}

void TableReader::error(std::string_view key, const std::string& message) {
  const toml::node* node = table_.get(key);
  errors_.add(file_, node ? node->source() : table_.source(), path(key), message);
}

// The node for `key` if present; records "missing" for a required absent key.
const toml::node* TableReader::present(std::string_view key, const KeySpec** spec) {
  *spec = spec_of(key);
  if (!*spec) throw std::logic_error("key '" + std::string(key) + "' is not in the schema");
  const toml::node* node = table_.get(key);
  if (!node && (*spec)->default_value.empty())
    errors_.add(file_, table_.source(), path(key),
                fmt::format("missing required key ({}{}{})", to_string((*spec)->type),
                            (*spec)->unit.empty() ? "" : ", in ", (*spec)->unit));
  return node;
}

bool TableReader::in_range(const KeySpec& spec, double v, std::string_view key,
                           const toml::node& node) {
  if (!std::isfinite(v) || v < spec.min || v > spec.max) {
    errors_.add(file_, node.source(), path(key),
                fmt::format("{} is out of range [{}, {}]", v, spec.min, spec.max));
    return false;
  }
  return true;
}

namespace {
std::string wrong_type(const KeySpec& spec, const toml::node& node) {
  std::ostringstream got;
  got << node.type();
  return fmt::format("expected {}, found {}", to_string(spec.type), got.str());
}
}  // namespace

namespace {
bool has_type(const toml::node& node, ValueType type) {
  switch (type) {
    case ValueType::Integer: return node.is_integer();
    case ValueType::Float: return node.is_integer() || node.is_floating_point();
    case ValueType::String: return node.is_string();
    case ValueType::Boolean: return node.is_boolean();
    case ValueType::FloatArray:
    case ValueType::StringArray:
    case ValueType::TableArray: return node.is_array();
    case ValueType::Table: return node.is_table();
  }
  return false;
}
}  // namespace

// The node for `key` if it is present and of the type its spec declares; otherwise
// nothing, with the problem recorded (a missing optional key is no problem).
const toml::node* TableReader::typed(std::string_view key, const KeySpec** spec) {
  const toml::node* node = present(key, spec);
  if (node && !has_type(*node, (*spec)->type)) {
    errors_.add(file_, node->source(), path(key), wrong_type(**spec, *node));
    return nullptr;
  }
  return node;
}

std::int64_t TableReader::integer(std::string_view key, std::int64_t fallback) {
  const KeySpec* spec;
  const toml::node* node = typed(key, &spec);
  if (!node) return fallback;
  const auto v = node->as_integer()->get();
  return in_range(*spec, static_cast<double>(v), key, *node) ? v : fallback;
}

double TableReader::number(std::string_view key, double fallback) {
  const KeySpec* spec;
  const toml::node* node = typed(key, &spec);
  if (!node) return fallback;
  const double v = *node->value<double>();  // integers too
  return in_range(*spec, v, key, *node) ? v : fallback;
}

std::string TableReader::string(std::string_view key, std::string fallback) {
  const KeySpec* spec;
  const toml::node* node = typed(key, &spec);
  return node ? node->as_string()->get() : fallback;
}

std::string TableReader::choice(std::string_view key, const std::vector<std::string_view>& allowed,
                                std::string fallback) {
  if (!has(key)) return string(key, std::move(fallback));
  std::string v = string(key, "");
  if (std::find(allowed.begin(), allowed.end(), v) != allowed.end()) return v;
  std::string list;
  for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
  error(key, fmt::format("'{}' is not one of: {}", v, list));
  return fallback;
}

bool TableReader::boolean(std::string_view key, bool fallback) {
  const KeySpec* spec;
  const toml::node* node = typed(key, &spec);
  return node ? node->as_boolean()->get() : fallback;
}

std::vector<double> TableReader::numbers(std::string_view key) {
  const KeySpec* spec;
  const toml::node* node = typed(key, &spec);
  if (!node) return {};
  const toml::array& arr = *node->as_array();
  if (spec->array_size && arr.size() != spec->array_size) {
    errors_.add(file_, node->source(), path(key),
                fmt::format("expected {} numbers, found {}", spec->array_size, arr.size()));
    return {};
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const toml::node& item = *arr.get(i);
    const std::string item_key = fmt::format("{}[{}]", key, i);
    if (!has_type(item, ValueType::Float)) {
      errors_.add(file_, item.source(), path(item_key), "expected a number");
      return {};
    }
    const double v = *item.value<double>();
    if (!in_range(*spec, v, item_key, item)) return {};
    out.push_back(v);
  }
  return out;
}

Vec3 TableReader::vec3(std::string_view key, const Vec3& fallback) {
  if (!has(key)) return fallback;
  const auto v = numbers(key);
  return v.size() == 3 ? Vec3(v[0], v[1], v[2]) : fallback;
}

std::vector<std::string> TableReader::strings(std::string_view key) {
  const KeySpec* spec;
  const toml::node* node = typed(key, &spec);
  if (!node) return {};
  std::vector<std::string> out;
  const toml::array& arr = *node->as_array();
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const toml::node& item = *arr.get(i);
    if (!item.is_string()) {
      errors_.add(file_, item.source(), path(fmt::format("{}[{}]", key, i)), "expected a string");
      return {};
    }
    out.push_back(item.as_string()->get());
  }
  return out;
}

const toml::table* TableReader::table(std::string_view key) {
  const KeySpec* spec;
  const toml::node* node = typed(key, &spec);
  return node ? node->as_table() : nullptr;
}

std::vector<const toml::table*> TableReader::tables(std::string_view key) {
  const KeySpec* spec;
  const toml::node* node = typed(key, &spec);
  if (!node) return {};
  std::vector<const toml::table*> out;
  const toml::array& arr = *node->as_array();
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const toml::node& item = *arr.get(i);
    if (!item.is_table()) {
      errors_.add(file_, item.source(), path(fmt::format("{}[{}]", key, i)), "expected a table");
      return {};
    }
    out.push_back(item.as_table());
  }
  return out;
}

Result<std::string> read_config_text(const std::string& path, std::size_t max_bytes) {
  // A pipe is read to its end, so that `--config <(make-config)` works; the daemon ends
  // on SIGINT/SIGTERM while it waits for one. A folder or a device is refused: reading
  // one can block or never end.
  const FileKind kind = file_kind(path);
  if (kind != FileKind::Regular && kind != FileKind::Fifo && kind != FileKind::Missing)
    return fail(fmt::format("{}: is {}, not a file to read", path, describe(kind)));
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(path + ": cannot read the file");
  // In chunks, so that memory grows with the file, not with the bound.
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes)
      return fail(fmt::format("{}: is larger than {} MiB, {}", path, max_bytes >> 20,
                              max_bytes == kMaxConfigBytes ? "too large for a config file"
                                                           : "the most read from a file of this kind"));
  }
  return text;
}

Result<toml::table> parse_toml(std::string_view text, const std::string& source_name) {
  try {
    return toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    return fail(fmt::format("{}:{}:{}: TOML syntax error: {}", source_name, b.line, b.column,
                            e.description()));
  }
}

std::string schema_markdown(const std::vector<const TableSpec*>& tables) {
  std::string out;
  for (const TableSpec* t : tables) {
    out += fmt::format("## `{}`\n\nRead by: {}.\n\n", t->name, t->reader);
    out += "| key | type | unit | default | range | meaning |\n|---|---|---|---|---|---|\n";
    for (const KeySpec& k : t->keys) {
      std::string range;
      if (std::isfinite(k.min) || std::isfinite(k.max))
        range = fmt::format("[{}, {}]", std::isfinite(k.min) ? fmt::format("{}", k.min) : "-inf",
                            std::isfinite(k.max) ? fmt::format("{}", k.max) : "inf");
      if (k.array_size) range += fmt::format("{}{} items", range.empty() ? "" : ", ", k.array_size);
      out += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", k.key, to_string(k.type),
                         k.unit.empty() ? "" : k.unit,
                         k.default_value.empty() ? "**required**" : std::string(k.default_value),
                         range, k.doc);
    }
    out += "\n";
  }
  return out;
}

}  // namespace covtrack
