// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/support/output.hpp"

#include "harness/support/errors.hpp"

#include <fstream>
#include <system_error>
#include <unistd.h>

namespace fs = std::filesystem;

namespace sonomap::harness {

static fs::path staging_name(const fs::path& final_path) {
  fs::path p = final_path;
  p += ".partial-" + std::to_string(::getpid());
  return p;
}

// The parent must exist and be writable; say so in terms of the path the user gave.
static void check_parent_writable(const fs::path& final_path) {
  fs::path parent = final_path.parent_path();
  if (parent.empty()) parent = ".";
  std::error_code ec;
  if (!fs::is_directory(parent, ec))
    throw InputError(final_path.string() + ": parent directory " + parent.string() +
                     " does not exist");
  if (::access(parent.c_str(), W_OK) != 0)
    throw InputError(final_path.string() + ": parent directory " + parent.string() +
                     " is not writable");
}

StagedDirectory::StagedDirectory(const fs::path& final_path, bool replace)
    : final_(final_path), staging_(staging_name(final_path)), replace_(replace) {
  check_parent_writable(final_);
  std::error_code ec;
  if (!replace_ && fs::exists(final_, ec))
    throw InputError(final_.string() + ": already exists");
  fs::remove_all(staging_, ec);
  if (!fs::create_directory(staging_, ec) || ec)
    throw InputError(final_.string() + ": cannot create " + staging_.string() + ": " +
                     ec.message());
}

StagedDirectory::~StagedDirectory() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
}

void StagedDirectory::commit() {
  std::error_code ec;
  if (replace_ && fs::exists(final_, ec)) {
    // Move the old one aside first so a failure never leaves neither.
    fs::path old = final_;
    old += ".old-" + std::to_string(::getpid());
    fs::rename(final_, old);
    fs::rename(staging_, final_);
    fs::remove_all(old, ec);
  } else {
    fs::rename(staging_, final_);
  }
  committed_ = true;
}

StagedFile::StagedFile(const fs::path& final_path)
    : final_(final_path), staging_(staging_name(final_path)) {
  check_parent_writable(final_);
}

StagedFile::~StagedFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(staging_, ec);
  }
}

void StagedFile::commit() {
  fs::rename(staging_, final_);
  committed_ = true;
}

void write_text_file(const fs::path& path, const std::string& text) {
  StagedFile file(path);
  {
    std::ofstream out(file.path(), std::ios::binary);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + file.path().string());
  }
  file.commit();
}

}  // namespace sonomap::harness
