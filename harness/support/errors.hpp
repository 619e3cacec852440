// SPDX-License-Identifier: GPL-3.0-or-later
// Bad input is reported as InputError: it names the file, line and key (or the frame and value).
// The CLI maps it to exit status 2.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace sonomap::harness {

class InputError : public std::runtime_error {
 public:
  // line <= 0: no line known. key empty: no key.
  InputError(const std::string& file, int line, const std::string& key, const std::string& what);
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

// Text from a user's file as an error message can show it: bytes outside printable ASCII as
// \xHH, at most `limit` characters of it (then "...").
std::string printable(const std::string& text, std::size_t limit = 80);

constexpr int kExitBadInput = 2;
constexpr int kExitFailure = 1;

}  // namespace sonomap::harness
