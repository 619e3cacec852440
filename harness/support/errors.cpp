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

InputError::InputError(const std::string& file, int line, const std::string& key,
                       const std::string& what)
    : std::runtime_error(located(file, line, key, what)) {}

}  // namespace sonomap::harness
