// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/support/output.hpp"

#include "harness/support/errors.hpp"
#include "harness/support/interrupt.hpp"
#include "harness/support/version.hpp"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <system_error>
#include <unistd.h>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

constexpr const char* kStagingTag = ".partial-";

// "out/", "out/." and "a/../out" name the folder "out": its staging name goes beside it.
fs::path tidy(const fs::path& path) {
  const fs::path p = path.lexically_normal();
  return p.has_filename() || p == p.root_path() ? p : p.parent_path();
}

fs::path staging_name(const fs::path& final_path) {
  fs::path p = final_path;
  p += kStagingTag + std::to_string(::getpid());
  return p;
}

fs::path parent_of(const fs::path& path) {
  const fs::path parent = path.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

[[noreturn]] void throw_write_error(const std::string& what, const fs::path& file, int error) {
  throw WriteError(what + " " + file.string() + ": " + std::strerror(error));
}

// Why a buffered write to `file` failed: a stream keeps no error code and errno may have been
// overwritten since, so the usual causes are checked first.
int write_failure_reason(const fs::path& file, int last_errno) {
  struct statvfs disk {};
  if (::statvfs(parent_of(file).c_str(), &disk) == 0 && disk.f_bavail == 0) return ENOSPC;
  struct rlimit limit {};
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (!ec && ::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
      size >= limit.rlim_cur)
    return EFBIG;
  const bool write_reason = last_errno == ENOSPC || last_errno == EFBIG ||
                            last_errno == EDQUOT || last_errno == EROFS;
  return write_reason ? last_errno : EIO;
}

std::string first_line(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string line;
  std::getline(in, line);
  return line;
}

// The parent must exist and be writable; say so in terms of the path the user gave.
void check_parent_writable(const fs::path& final_path) {
  const fs::path parent = parent_of(final_path);
  std::error_code ec;
  if (!fs::is_directory(parent, ec))
    throw InputError(final_path.string() + ": parent directory " + parent.string() +
                     " does not exist");
  if (::access(parent.c_str(), W_OK) != 0)
    throw InputError(final_path.string() + ": parent directory " + parent.string() +
                     " is not writable");
}

// Every byte of `data` into a new file, fsynced (write_fully).
void write_all(const fs::path& file, const std::string& data) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw_write_error("cannot create", file, errno);
  if (const int error = write_fully(fd, data.data(), data.size()); error != 0) {
    ::close(fd);
    throw_write_error("writing", file, error);
  }
  if (::fsync(fd) != 0 && errno != EINVAL) {
    const int error = errno;
    ::close(fd);
    throw_write_error("writing", file, error);
  }
  if (::close(fd) != 0) throw_write_error("writing", file, errno);
}

// Flushes a file or folder to the disk (EINVAL: the file system has nothing to flush).
void sync_path(const fs::path& path, bool directory) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | (directory ? O_DIRECTORY : 0));
  if (fd < 0) throw_write_error("cannot open", path, errno);
  const int rc = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (rc != 0 && error != EINVAL) throw_write_error("writing", path, error);
}

// Every file and folder under `dir`, and `dir` itself: whatever a writer left in its buffers
// reaches the disk (or fails here) before the result is published.
void sync_tree(const fs::path& dir) {
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::file_status status = it->symlink_status(ec);
    if (fs::is_regular_file(status)) sync_path(it->path(), false);
    else if (fs::is_directory(status)) sync_path(it->path(), true);
  }
  if (ec) throw_write_error("cannot list", dir, ec.value());
  sync_path(dir, true);
}

// A staging folder "<name>.partial-<pid>" whose process no longer exists, marked as ours.
bool stale_staging_folder(const fs::directory_entry& entry) {
  const std::string name = entry.path().filename().string();
  const auto tag = name.rfind(kStagingTag);
  if (tag == std::string::npos) return false;
  const std::string digits = name.substr(tag + std::strlen(kStagingTag));
  if (digits.empty() || digits.size() > 9 ||
      digits.find_first_not_of("0123456789") != std::string::npos)
    return false;
  const pid_t pid = static_cast<pid_t>(std::stol(digits));
  if (pid <= 0 || pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) return false;
  std::error_code ec;
  return entry.is_directory(ec) && !entry.is_symlink(ec) && is_sonomap_result(entry.path());
}

void remove_stale_staging(const fs::path& folder) {
  std::error_code ec;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
    if (stale_staging_folder(*it)) stale.push_back(it->path());
  for (const fs::path& p : stale) fs::remove_all(p, ec);
}

std::string marker_text(const std::string& command) {
  return "sonomap " + command + " " + code_version() + "\n";
}

// Renames `staging` to `final_path`; an existing final (checked to be ours) is swapped out in
// the same step and then removed, so there is never a moment with neither.
void publish(const fs::path& staging, const fs::path& final_path) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(final_path, ec))) {
    if (::rename(staging.c_str(), final_path.c_str()) != 0)
      throw_write_error("cannot publish", final_path, errno);
  } else if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, final_path.c_str(),
                         RENAME_EXCHANGE) == 0) {
    fs::remove_all(staging, ec);  // now the earlier result
  } else {
    if (errno != EINVAL && errno != ENOSYS) throw_write_error("cannot publish", final_path, errno);
    // A file system without atomic exchange: move the old one aside under a staging name
    // (a stale-staging sweep removes it if we die here), then rename.
    fs::path aside = final_path;
    aside += ".old" + staging_name(fs::path()).string();
    if (::rename(final_path.c_str(), aside.c_str()) != 0)
      throw_write_error("cannot publish", final_path, errno);
    if (::rename(staging.c_str(), final_path.c_str()) != 0) {
      const int error = errno;
      ::rename(aside.c_str(), final_path.c_str());  // the earlier result back in its place
      throw_write_error("cannot publish", final_path, error);
    }
    fs::remove_all(aside, ec);
  }
  sync_path(parent_of(final_path), true);
}

// The weakly canonical form (symbolic links, "." and ".." resolved as far as the path exists),
// without a trailing separator.
fs::path canonical_form(const fs::path& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return tidy(ec ? fs::absolute(path) : p);
}

// `inner` is `outer` or lies somewhere below it (both in canonical form).
bool within(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i)
    if (i == inner.end() || *i != *o) return false;
  return true;
}

}  // namespace

int write_fully(int fd, const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(fd, p, bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? errno : EIO;
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
  return 0;
}

bool is_sonomap_result(const fs::path& dir) {
  std::error_code ec;
  const fs::path marker = dir / kResultMarker;
  return fs::is_regular_file(fs::symlink_status(marker, ec)) &&
         first_line(marker).rfind("sonomap ", 0) == 0;
}

bool in_sonomap_result(const fs::path& file) { return is_sonomap_result(parent_of(file)); }

bool is_sonomap_json(const fs::path& file) {
  std::error_code ec;
  if (fs::file_size(file, ec) > (64u << 20) || ec) return false;
  std::ifstream in(file, std::ios::binary);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_object() && j.contains("code_version") && j["code_version"].is_string();
}

bool first_line_is(const fs::path& file, const std::string& header) {
  return first_line(file) == header;
}

void check_not_an_input(const fs::path& out, const std::vector<fs::path>& inputs) {
  const fs::path o = canonical_form(out);
  for (const fs::path& input : inputs) {
    if (input.empty()) continue;
    const fs::path i = canonical_form(input);
    const char* relation = o == i            ? "is"
                           : within(i, o)    ? "contains"
                           : within(o, i)    ? "lies inside"
                                             : nullptr;
    if (relation)
      throw InputError("output " + out.string() + " " + relation + " the input " +
                       input.string() + "; choose another --out");
  }
}

void check_output_directory(const fs::path& out, const std::vector<fs::path>& inputs) {
  check_not_an_input(out, inputs);
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(out, ec);
  if (!fs::exists(status)) return;
  if (fs::is_directory(status) && (is_sonomap_result(out) || fs::is_empty(out, ec))) return;
  throw InputError(out.string() + " exists and is not a sonomap result; choose another --out");
}

void check_output_file(const fs::path& out, const Recognise& ours,
                       const std::vector<fs::path>& inputs) {
  check_not_an_input(out, inputs);
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(out, ec);
  if (!fs::exists(status)) return;
  if (fs::is_regular_file(status) && ours && ours(out)) return;
  throw InputError(out.string() + " exists and was not written by sonomap; choose another --out");
}

void prepare_output_directory(const fs::path& out, const std::string& command,
                              const std::vector<fs::path>& inputs) {
  check_output_directory(out, inputs);
  check_parent_writable(out);
  if (is_sonomap_result(out)) return;
  std::error_code ec;
  fs::create_directory(out, ec);
  if (ec) throw_write_error("cannot create", out, ec.value());
  write_all(out / kResultMarker, marker_text(command));
  sync_path(out, true);
  sync_path(parent_of(out), true);
}

void mark_as_result(const fs::path& dir, const std::string& command) {
  write_all(dir / kResultMarker, marker_text(command));
  sync_path(dir, true);
}

StagedDirectory::StagedDirectory(const fs::path& final_path, const std::string& command,
                                 const std::vector<fs::path>& inputs)
    : final_(tidy(final_path)), staging_(staging_name(final_)) {
  check_output_directory(final_, inputs);
  check_parent_writable(final_);
  install_interrupt_handler();
  remove_stale_staging(parent_of(final_));
  std::error_code ec;
  if (fs::exists(fs::symlink_status(staging_, ec))) {
    // Left by an earlier process that had our pid: removed only if it is marked as ours.
    if (!is_sonomap_result(staging_))
      throw InputError(staging_.string() + " exists and is not a sonomap result; remove it");
    fs::remove_all(staging_, ec);
  }
  if (!fs::create_directory(staging_, ec) || ec)
    throw_write_error("cannot create", staging_, ec ? ec.value() : EEXIST);
  try {
    write_all(staging_ / kResultMarker, marker_text(command));
  } catch (...) {
    fs::remove_all(staging_, ec);
    throw;
  }
}

StagedDirectory::~StagedDirectory() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
}

void StagedDirectory::commit() {
  throw_if_interrupted();
  sync_tree(staging_);
  check_output_directory(final_);  // still nothing of the user's there
  throw_if_interrupted();          // the last moment: after the rename the result is whole
  publish(staging_, final_);
  committed_ = true;
}

StagedFile::StagedFile(const fs::path& final_path, const Recognise& ours,
                       const std::vector<fs::path>& inputs)
    : final_(tidy(final_path)), staging_(staging_name(final_)) {
  check_output_file(final_, ours, inputs);
  check_parent_writable(final_);
  install_interrupt_handler();
}

StagedFile::~StagedFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(staging_, ec);
  }
}

void StagedFile::commit() {
  throw_if_interrupted();
  sync_path(staging_, false);
  throw_if_interrupted();
  if (::rename(staging_.c_str(), final_.c_str()) != 0)
    throw_write_error("cannot publish", final_, errno);
  committed_ = true;
  sync_path(parent_of(final_), true);
}

void StagedFile::write(const std::string& text) { write_all(staging_, text); }

void write_text_file(const fs::path& path, const std::string& text, const Recognise& ours) {
  StagedFile file(path, ours);
  file.write(text);
  file.commit();
}

void close_checked(std::ofstream& stream, const fs::path& file) {
  if (stream.is_open()) stream.close();
  if (!stream.fail()) return;
  throw_write_error("writing", file, write_failure_reason(file, errno));
}

}  // namespace sonomap::harness
