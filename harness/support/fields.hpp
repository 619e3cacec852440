// SPDX-License-Identifier: GPL-3.0-or-later
// One declaration per setting. A Field names one setting of a config struct (bound to that
// struct's member), with its unit, its physical bounds and a one-line doc. The same table reads
// `--set key=value`, checks the bounds, writes the value to summary.json, lists the defaults in
// `--help` and makes the key reference in docs/settings.md (checked by a test).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <variant>
#include <vector>

namespace sonomap::harness {

// Physical limits shared by every setting and scenario key (documented in docs/settings.md):
// a place within 10 km of the origin, a sensor range up to 100 m, a voxel of 1 mm to 10 m,
// rates up to 1 kHz, up to 10 million frames.
constexpr double kMaxPosition = 1e4;  // m
constexpr double kMaxRange = 100.0;   // m
constexpr double kMinVoxel = 1e-3;    // m
constexpr double kMaxVoxel = 10.0;    // m
constexpr double kMaxRate = 1000.0;   // Hz
constexpr int kMaxFrames = 10000000;

// The one number parser: the whole text is a finite decimal number.
bool parse_number(const std::string& text, double& value);
// Seeds: a whole number in [0, kMaxSeed], all digits (no sign, no exponent).
constexpr std::uint64_t kMaxSeed = (std::uint64_t{1} << 63) - 1;
bool parse_seed(const std::string& text, std::uint64_t& value);
// The shortest of 15 or 17 significant digits that reads back as exactly `value`.
std::string number_text(double value);

// Inclusive bounds [min, max]; `min_open` makes the lower one exclusive (min, max].
struct Range {
  double min = 0.0;
  double max = 0.0;
  bool min_open = false;
  bool contains(double v) const;
  std::string text() const;  // "(0, 100]", "[1, 36000]"
};

// A setting with a fixed set of names (an enum): get/set by index into `names`.
struct Choice {
  std::vector<std::string> names;
  std::function<int()> get;
  std::function<void(int)> set;
};

using FieldTarget = std::variant<double*, int*, bool*, std::uint64_t*, Choice>;

struct Field {
  std::string name;
  FieldTarget target;
  std::string unit;  // "m", "Hz", "px", "" (no unit)
  Range range;       // numbers only
  std::string doc;
  std::vector<std::string> aliases = {};  // other names accepted on input
};

using FieldTable = std::vector<Field>;

// Field builders: a number in [lo, hi], a number in (0, hi], a whole number in [lo, hi],
// a flag, a choice.
Field number(std::string name, double* v, std::string unit, double lo, double hi, std::string doc);
Field positive(std::string name, double* v, std::string unit, double hi, std::string doc);
Field whole(std::string name, int* v, int lo, int hi, std::string doc);
Field flag(std::string name, bool* v, std::string doc);

const Field* find_field(const FieldTable& table, const std::string& name);
std::string field_names(const FieldTable& table);  // "a, b, c"
std::string field_value(const Field& field);       // the current value as text
std::string field_type(const Field& field);        // "number", "whole number", "true/false", ...
// The bounds as users read them: "(0, 100] m", "true or false", "one of a, b".
std::string field_rule(const Field& field);

// Parses `text` into the field, bounds checked. Errors are InputError naming `where` (e.g.
// "--set mapper.voxel=0"), the key and the rule.
void set_field(const Field& field, const std::string& key, const std::string& text,
               const std::string& where);
// Throws InputError naming `where` and `key` unless `v` is finite and within the field's range.
void check_number(const Field& field, const std::string& key, double v, const std::string& where);

// The key reference as a markdown table: | key | default | range | meaning |.
std::string markdown_table(const FieldTable& table, const std::string& prefix);
// The same as plain text for `--help`: "  prefix.name = default unit  range  doc".
std::string help_lines(const FieldTable& table, const std::string& prefix);

}  // namespace sonomap::harness
