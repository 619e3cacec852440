// SPDX-License-Identifier: GPL-3.0-or-later
// The output-safety tests: the sonomap executable started as a child we can limit (file size)
// or signal, and the short run they all use.
#pragma once

#include "cli_support.hpp"
#include "run_support.hpp"
#include "test_scenario_files.hpp"

#include <csignal>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace sonomap::test {

inline std::filesystem::path smoke_scene() { return shipped("scenes/smoke.yaml"); }

// `sonomap run` of a few frames of the smoke scene with the small camera, nothing drawn.
inline std::vector<std::string> short_run(const std::filesystem::path& scenario,
                                          const std::filesystem::path& out, int frames = 3) {
  std::vector<std::string> args{"--quiet", "run", scenario.string(), "--out", out.string(),
                                "--mapper", "depth_only", "--frames", std::to_string(frames),
                                "--pictures", "-1", "--sweeps", "-1"};
  for (const std::string& o : small_camera()) args.insert(args.end(), {"--set", o});
  return args;
}

// Starts sonomap with stdout and stderr into `log`. file_size_limit > 0: RLIMIT_FSIZE in the
// child, with SIGXFSZ ignored so that a write past it fails with EFBIG as on a full disk.
inline pid_t start_sonomap(const std::vector<std::string>& arguments, const std::filesystem::path& log,
                           rlim_t file_size_limit = 0) {
  const char* exe = std::getenv("SONOMAP_EXE");
  if (!exe) FAIL("SONOMAP_EXE is not set: run this test under ctest");
  std::vector<std::string> argv{exe};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  std::vector<char*> args;
  for (auto& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {  // only async-signal-safe calls until exec
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) ::dup2(fd, STDOUT_FILENO), ::dup2(fd, STDERR_FILENO);
    if (file_size_limit > 0) {
      const struct rlimit limit{file_size_limit, file_size_limit};
      ::setrlimit(RLIMIT_FSIZE, &limit);
      ::signal(SIGXFSZ, SIG_IGN);
    }
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  return pid;
}

// The exit status of a child (128 + signal if a signal killed it).
inline int wait_status(pid_t pid) {
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid) return -1;
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A process id that belonged to a process that has exited.
inline pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

// Entries of `dir` whose name holds ".partial-" (staging leftovers).
inline std::vector<std::string> partial_entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.find(".partial-") != std::string::npos) names.push_back(name);
  }
  return names;
}

}  // namespace sonomap::test
