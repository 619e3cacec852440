// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/support/fields.hpp"

#include "harness/support/errors.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sonomap::harness {

bool parse_number(const std::string& text, double& value) {
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(value);
}

std::string number_text(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", value);
  if (std::strtod(buf, nullptr) != value) std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

bool parse_seed(const std::string& text, std::uint64_t& value) {
  if (text.empty() || text.size() > 19 || text.find_first_not_of("0123456789") != std::string::npos)
    return false;
  value = std::strtoull(text.c_str(), nullptr, 10);
  return value <= kMaxSeed;
}

bool Range::contains(double v) const {
  return std::isfinite(v) && (min_open ? v > min : v >= min) && v <= max;
}

std::string Range::text() const {
  return (min_open ? "(" : "[") + number_text(min) + ", " + number_text(max) + "]";
}

Field number(std::string name, double* v, std::string unit, double lo, double hi, std::string doc) {
  return {std::move(name), v, std::move(unit), {lo, hi, false}, std::move(doc)};
}

Field positive(std::string name, double* v, std::string unit, double hi, std::string doc) {
  return {std::move(name), v, std::move(unit), {0.0, hi, true}, std::move(doc)};
}

Field whole(std::string name, int* v, int lo, int hi, std::string doc) {
  return {std::move(name), v, "", {double(lo), double(hi), false}, std::move(doc)};
}

Field flag(std::string name, bool* v, std::string doc) {
  return {std::move(name), v, "", {}, std::move(doc)};
}

const Field* find_field(const FieldTable& table, const std::string& name) {
  for (const Field& f : table) {
    if (f.name == name) return &f;
    for (const std::string& alias : f.aliases)
      if (alias == name) return &f;
  }
  return nullptr;
}

std::string field_names(const FieldTable& table) {
  std::string names;
  for (const Field& f : table) names += (names.empty() ? "" : ", ") + f.name;
  return names;
}

namespace {

std::string choice_list(const Choice& c) {
  std::string list;
  for (const std::string& n : c.names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

template <typename... Fs>
struct Overloaded : Fs... {
  using Fs::operator()...;
};
template <typename... Fs>
Overloaded(Fs...) -> Overloaded<Fs...>;

}  // namespace

std::string field_value(const Field& field) {
  return std::visit(Overloaded{[](const double* v) { return number_text(*v); },
                               [](const int* v) { return std::to_string(*v); },
                               [](const bool* v) { return std::string(*v ? "true" : "false"); },
                               [](const std::uint64_t* v) { return std::to_string(*v); },
                               [](const Choice& c) { return c.names.at(std::size_t(c.get())); }},
                    field.target);
}

std::string field_type(const Field& field) {
  return std::visit(Overloaded{[](const double*) { return std::string("number"); },
                               [](const int*) { return std::string("whole number"); },
                               [](const bool*) { return std::string("true/false"); },
                               [](const std::uint64_t*) { return std::string("whole number"); },
                               [](const Choice&) { return std::string("name"); }},
                    field.target);
}

std::string field_rule(const Field& field) {
  if (std::holds_alternative<bool*>(field.target)) return "true or false";
  if (const Choice* c = std::get_if<Choice>(&field.target)) return "one of " + choice_list(*c);
  if (std::holds_alternative<std::uint64_t*>(field.target)) return "[0, 2^63-1]";
  return field.range.text() + (field.unit.empty() ? "" : " " + field.unit);
}

void check_number(const Field& field, const std::string& key, double v, const std::string& where) {
  if (!field.range.contains(v))
    throw InputError(where + ": key '" + key + "': " + number_text(v) + " is out of range: expected " +
                     field_type(field) + " in " + field_rule(field));
}

void set_field(const Field& field, const std::string& key, const std::string& text,
               const std::string& where) {
  const auto bad = [&] {
    return InputError(where + ": key '" + key + "': expected " + field_type(field) + " in " +
                      field_rule(field) + ", got '" + text + "'");
  };
  if (bool* const* b = std::get_if<bool*>(&field.target)) {
    if (text == "true" || text == "on" || text == "1") **b = true;
    else if (text == "false" || text == "off" || text == "0") **b = false;
    else throw bad();
    return;
  }
  if (const Choice* c = std::get_if<Choice>(&field.target)) {
    for (std::size_t i = 0; i < c->names.size(); ++i)
      if (c->names[i] == text) return c->set(static_cast<int>(i));
    throw bad();
  }
  if (std::uint64_t* const* u = std::get_if<std::uint64_t*>(&field.target)) {
    // Seeds: every digit counts (a double would round them).
    std::uint64_t value = 0;
    if (!parse_seed(text, value)) throw bad();
    **u = value;
    return;
  }
  double v = 0.0;
  if (!parse_number(text, v)) throw bad();
  const bool integral = !std::holds_alternative<double*>(field.target);
  if (integral && v != std::floor(v)) throw bad();
  check_number(field, key, v, where);
  if (double* const* d = std::get_if<double*>(&field.target)) **d = v;
  else **std::get_if<int*>(&field.target) = static_cast<int>(v);
}

std::string markdown_table(const FieldTable& table, const std::string& prefix) {
  std::string rows = "| key | default | range | meaning |\n| --- | --- | --- | --- |\n";
  for (const Field& f : table) {
    std::string names = "`" + prefix + f.name + "`";
    for (const std::string& a : f.aliases) names += " (or `" + prefix + a + "`)";
    rows += "| " + names + " | " + field_value(f) + " | " + field_rule(f) + " | " + f.doc + " |\n";
  }
  return rows;
}

std::string help_lines(const FieldTable& table, const std::string& prefix) {
  std::string lines;
  for (const Field& f : table) {
    std::string names = prefix + f.name;
    for (const std::string& a : f.aliases) names += " (or " + prefix + a + ")";
    lines += "  " + names + " = " + field_value(f) + "  " + field_rule(f) + "  " + f.doc + "\n";
  }
  return lines;
}

}  // namespace sonomap::harness
