// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/support/errors.hpp"

namespace sonomap::harness {

static std::string located(const std::string& file, int line, const std::string& key,
                           const std::string& what) {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  s += ": ";
  if (!key.empty()) s += "key '" + key + "': ";
  return s + what;
}

std::string printable(const std::string& text, std::size_t limit) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < limit; ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte >= 0x20 && byte < 0x7f) {
      out += static_cast<char>(byte);
    } else {
      out += "\\x";
      out += kHex[byte >> 4];
      out += kHex[byte & 15];
    }
  }
  if (text.size() > limit) out += "...";
  return out;
}

InputError::InputError(const std::string& file, int line, const std::string& key,
                       const std::string& what)
    : std::runtime_error(located(file, line, key, what)) {}

}  // namespace sonomap::harness
