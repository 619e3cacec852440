// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/support/subprocess.hpp"

#include "harness/support/errors.hpp"
#include "harness/support/interrupt.hpp"
#include "harness/support/output.hpp"

#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

extern char** environ;

namespace sonomap::harness {
namespace {

// posix_spawnp of argv (looked up in PATH) with `actions`, which it destroys; 0 or an errno.
int spawn(pid_t& pid, const std::vector<std::string>& argv, posix_spawn_file_actions_t& actions,
          const posix_spawnattr_t* attributes = nullptr) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const int error = ::posix_spawnp(&pid, args[0], &actions, attributes, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return error;
}


// Waits for `pid`; past `timeout_s` or on Ctrl-C (interrupt.hpp) sends SIGKILL to `kill_target`
// (the pid, or minus its process group). The exit status, 128 + signal when a signal ended it,
// -1 when waiting failed.
int wait_with_deadline(pid_t pid, pid_t kill_target, double timeout_s, bool& timed_out) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) return -1;
    const bool late = std::chrono::steady_clock::now() >= deadline;
    if (late || interrupt_requested()) {
      timed_out = late;
      ::kill(kill_target, SIGKILL);
      ::waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
}

}  // namespace

int run_program(const std::vector<std::string>& argv, std::string* output) {
  if (argv.empty()) return -1;
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) return -1;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);

  pid_t pid = 0;
  const int spawn_error = spawn(pid, argv, actions);
  ::close(pipe_fds[1]);

  std::string captured;
  char buffer[4096];
  ssize_t n;
  while ((n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0) captured.append(buffer, n);
  ::close(pipe_fds[0]);
  if (output) *output = captured;
  if (spawn_error != 0) return -1;

  int status = 0;
  if (::waitpid(pid, &status, 0) < 0) return -1;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return -1;
}

int run_program_with_timeout(const std::vector<std::string>& argv, double timeout_s, bool& timed_out) {
  timed_out = false;
  if (argv.empty()) return -1;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);  // its own group: a timeout ends its children too
  pid_t pid = 0;
  const int spawn_error = spawn(pid, argv, actions, &attributes);
  posix_spawnattr_destroy(&attributes);
  if (spawn_error != 0) return -1;

  return wait_with_deadline(pid, -pid, timeout_s, timed_out);
}

// The sanitizers' death hook, defined only in sanitized builds: libFuzzer sets it to save the
// input of a crash. In run_isolated's child a sanitizer's report is the screened library's
// crash, which the parent turns into an error naming the file, not a finding of sonomap's.
extern "C" void __sanitizer_set_death_callback(void (*callback)()) __attribute__((weak));

int run_isolated(const std::function<int()>& work, double timeout_s, bool& timed_out) {
  timed_out = false;
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {  // the child: no destructors, atexit handlers or stdio flushes of the parent's
    // It dies with the program: a parent killed outright (SIGKILL, or libFuzzer ending on a
    // timeout) left a child looping in assimp behind, for an hour, until killed by hand.
    if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || ::getppid() != parent) ::_exit(127);
    // A crash ends the child as a crash, whatever handler the process had installed (a
    // sanitizer's or libFuzzer's report would claim the parent's crash: fuzz/fuzz_mesh).
    for (const int fatal : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL}) std::signal(fatal, SIG_DFL);
    if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(nullptr);
    int code = 127;
    try {
      code = work();
    } catch (...) {
    }
    ::_exit(code);
  }
  return wait_with_deadline(pid, pid, timeout_s, timed_out);
}

int screen_file(const std::filesystem::path& file, const std::string& readers, const std::function<int()>& read) {
  constexpr double kTimeoutS = 30.0;
  constexpr int kFirstFailure = 100;  // read's own codes lie below; 127 and 128 + signal above
  bool timed_out = false;
  const int status = run_isolated(read, kTimeoutS, timed_out);
  throw_if_interrupted();
  if (status == -1) throw std::runtime_error("cannot start a process to read " + file.string());
  if (timed_out) throw InputError(file.string(), 0, "", readers + " did not finish within 30 s (a corrupt file)");
  if (status >= kFirstFailure)
    throw InputError(file.string(), 0, "",
                     readers + " crashed on it (a corrupt file; exit status " + std::to_string(status) + ")");
  return status;
}

}  // namespace sonomap::harness

namespace sonomap::harness {

ChildOutput::ChildOutput() : fd_(::memfd_create("sonomap-child-output", MFD_CLOEXEC)) {
  if (fd_ < 0) throw std::runtime_error(std::string("cannot make a memory file for a child process: ") + std::strerror(errno));
}

ChildOutput::~ChildOutput() { ::close(fd_); }

bool ChildOutput::write(const void* data, std::size_t bytes) { return write_fully(fd_, data, bytes) == 0; }

std::string ChildOutput::read() const {
  struct stat info {};
  if (::fstat(fd_, &info) != 0) throw std::runtime_error("cannot read a child process's output");
  std::string bytes(static_cast<std::size_t>(info.st_size), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pread(fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error("cannot read a child process's output");
    done += static_cast<std::size_t>(n);
  }
  return bytes;
}

bool program_in_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string folders = path ? path : "";
  size_t start = 0;
  while (start <= folders.size()) {
    const size_t end = std::min(folders.find(':', start), folders.size());
    const std::string folder = folders.substr(start, end - start);
    const std::string candidate = (folder.empty() ? "." : folder) + "/" + program;
    if (::access(candidate.c_str(), X_OK) == 0) return true;
    start = end + 1;
  }
  return false;
}

PipedProgram::PipedProgram(const std::vector<std::string>& argv) {
  int in_fds[2], out_fds[2];
  if (argv.empty() || ::pipe2(in_fds, O_CLOEXEC) != 0) throw std::runtime_error("cannot make a pipe");
  if (::pipe2(out_fds, O_CLOEXEC) != 0) {
    ::close(in_fds[0]);
    ::close(in_fds[1]);
    throw std::runtime_error("cannot make a pipe");
  }
  // A program that stops reading must not end sonomap with SIGPIPE: write() reports it.
  std::signal(SIGPIPE, SIG_IGN);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in_fds[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, out_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, out_fds[1], STDERR_FILENO);
  pid_t pid = 0;
  const int spawn_error = spawn(pid, argv, actions);
  ::close(in_fds[0]);
  ::close(out_fds[1]);
  stdin_fd_ = in_fds[1];
  output_fd_ = out_fds[0];
  if (spawn_error != 0) {
    ::close(stdin_fd_);
    ::close(output_fd_);
    throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(spawn_error));
  }
  pid_ = pid;
  reader_ = std::thread([this] {
    char buffer[4096];
    ssize_t n;
    while ((n = ::read(output_fd_, buffer, sizeof buffer)) > 0) output_.append(buffer, n);
  });
}

PipedProgram::~PipedProgram() {
  if (pid_ > 0) ::kill(pid_, SIGKILL);
  finish();
}

bool PipedProgram::write(const void* data, size_t bytes) {
  return stdin_fd_ >= 0 && write_fully(stdin_fd_, data, bytes) == 0;
}

int PipedProgram::finish(std::string* output) {
  if (stdin_fd_ >= 0) ::close(stdin_fd_);
  stdin_fd_ = -1;
  int status = -1;
  if (pid_ > 0) {
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
  }
  if (reader_.joinable()) reader_.join();
  if (output_fd_ >= 0) ::close(output_fd_);
  output_fd_ = -1;
  if (output) *output = output_;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace sonomap::harness
