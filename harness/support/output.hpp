// SPDX-License-Identifier: GPL-3.0-or-later
// Outputs appear whole or not at all: everything is written under a temporary name in the
// same directory and renamed into place when complete.
#pragma once

#include <filesystem>
#include <string>

namespace sonomap::harness {

// A directory built at "<final>.partial-<pid>" and renamed to <final> by commit().
// Destroyed without commit (error, exception, Ctrl-C unwinding): the partial directory is removed.
// An existing <final> is an error unless `replace` is set (then it is replaced at commit).
class StagedDirectory {
 public:
  explicit StagedDirectory(const std::filesystem::path& final_path, bool replace = true);
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  const std::filesystem::path& path() const { return staging_; }
  const std::filesystem::path& final_path() const { return final_; }
  void commit();

 private:
  std::filesystem::path final_;
  std::filesystem::path staging_;
  bool replace_;
  bool committed_ = false;
};

// A single file written at "<final>.partial-<pid>" and renamed by commit().
class StagedFile {
 public:
  explicit StagedFile(const std::filesystem::path& final_path);
  ~StagedFile();
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;
  const std::filesystem::path& path() const { return staging_; }
  void commit();

 private:
  std::filesystem::path final_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

// Writes text to a file atomically (temporary name + rename).
void write_text_file(const std::filesystem::path& path, const std::string& text);

}  // namespace sonomap::harness
