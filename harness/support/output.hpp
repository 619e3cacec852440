// SPDX-License-Identifier: GPL-3.0-or-later
// The output rules every command that writes follows (docs/outputs.md):
// - an output is written under "<final>.partial-<pid>" and published by one rename, after every
//   file and folder is fsynced; a failed write is a WriteError (exit 1) and nothing is published;
// - --out may name nothing, an empty folder, or a result sonomap wrote (it holds the marker
//   file .sonomap-result); a single file may replace only a file sonomap recognises as its own;
//   anything else, and an output that is, contains or lies inside an input, is an InputError
//   (exit 2) and nothing is touched;
// - staging folders of processes that no longer exist are removed from the folder written to;
// - an interrupt (interrupt.hpp) up to the publishing rename removes the staged output.
#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace sonomap::harness {

// A write that failed (disk full, file too large, I/O error): exit status 1.
class WriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The file in every published result directory: "sonomap <command> <version>" on one line.
inline constexpr const char* kResultMarker = ".sonomap-result";
bool is_sonomap_result(const std::filesystem::path& dir);

// Decides whether an existing file at a single-file output is one sonomap wrote.
using Recognise = std::function<bool(const std::filesystem::path&)>;
// The default for files sonomap writes inside its own results: their folder holds the marker.
bool in_sonomap_result(const std::filesystem::path& file);
// A JSON object with sonomap's "code_version" key (bench --json, summary.json).
bool is_sonomap_json(const std::filesystem::path& file);
// A text file whose first line is exactly `header` (a CSV sonomap wrote).
bool first_line_is(const std::filesystem::path& file, const std::string& header);

// InputError unless `out` is neither, nor contains, nor lies inside any of `inputs` (empty
// paths are skipped). Compared by weakly canonical paths, so links and ".." do not hide it.
void check_not_an_input(const std::filesystem::path& out,
                        const std::vector<std::filesystem::path>& inputs);
// The checks of a result directory, before any work: not an input, and replaceable.
void check_output_directory(const std::filesystem::path& out,
                            const std::vector<std::filesystem::path>& inputs = {});
// The checks of a single-file output: not an input; absent, or an existing file `ours` accepts.
void check_output_file(const std::filesystem::path& out, const Recognise& ours,
                       const std::vector<std::filesystem::path>& inputs = {});
// A result directory written in place over time (compare: resumable): checked as above, then
// created with its marker if new.
void prepare_output_directory(const std::filesystem::path& out, const std::string& command,
                              const std::vector<std::filesystem::path>& inputs = {});

// Marks an existing folder as a sonomap result (report, into a folder of runs gathered by hand).
void mark_as_result(const std::filesystem::path& dir, const std::string& command);

// A result directory built at "<final>.partial-<pid>" (marked from the start, so a staging
// folder left by a killed process is recognisably ours) and published by commit(), which
// replaces an earlier result atomically. Destroyed without commit: the staging folder is removed.
class StagedDirectory {
 public:
  StagedDirectory(const std::filesystem::path& final_path, const std::string& command,
                  const std::vector<std::filesystem::path>& inputs = {});
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  const std::filesystem::path& path() const { return staging_; }
  const std::filesystem::path& final_path() const { return final_; }
  void commit();

 private:
  std::filesystem::path final_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

// A single file written at "<final>.partial-<pid>" and renamed by commit(). An existing file
// at <final> is replaced only if `ours` recognises it (empty: never).
class StagedFile {
 public:
  explicit StagedFile(const std::filesystem::path& final_path, const Recognise& ours = {},
                      const std::vector<std::filesystem::path>& inputs = {});
  ~StagedFile();
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;
  const std::filesystem::path& path() const { return staging_; }
  // Writes `text` as the whole file, checked and fsynced (WriteError with the reason).
  void write(const std::string& text);
  void commit();

 private:
  std::filesystem::path final_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

// Writes text to a file atomically and checked (staged, fsynced, renamed).
void write_text_file(const std::filesystem::path& path, const std::string& text,
                     const Recognise& ours = in_sonomap_result);

// Closes a stream that wrote `file`; WriteError with the reason if any write to it failed.
void close_checked(std::ofstream& stream, const std::filesystem::path& file);

// Every byte of `data` to file descriptor `fd` (short writes continue, EINTR retries): 0, or
// the errno that stopped it (EIO when a write wrote nothing).
int write_fully(int fd, const void* data, std::size_t bytes);

}  // namespace sonomap::harness
