// SPDX-License-Identifier: GPL-3.0-or-later
// Running helper programs (gnuplot) without a shell, so paths with spaces or quotes are safe.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace sonomap::harness {

// Runs argv[0] (looked up in PATH) with the given arguments, stdout and stderr captured into
// `output`. Returns the exit status, or -1 when the program could not be started.
int run_program(const std::vector<std::string>& argv, std::string* output = nullptr);

// Runs argv[0] (looked up in PATH) with stdin from /dev/null and stdout/stderr inherited, in
// its own process group. Past `timeout_s` seconds, or on Ctrl-C (interrupt.hpp), the whole
// group is killed. Returns the exit status (128 + signal when killed by one), -1 when the
// program could not be started; `timed_out` tells whether the time limit ended it.
int run_program_with_timeout(const std::vector<std::string>& argv, double timeout_s, bool& timed_out);

// Runs `work` in a forked child process and returns its result as the child's exit status (128 +
// signal when it crashed, 127 when it threw, -1 when no child could be made). For library code
// that may crash or loop on hostile input (HDF5 on a corrupt SOFA file): the crash stays in the
// child. Past `timeout_s` or on Ctrl-C the child is killed; `timed_out` tells which.
int run_isolated(const std::function<int()>& work, double timeout_s, bool& timed_out);

// Opens a user's file with `read` in a child process first (run_isolated), for libraries that
// may crash or loop on a corrupt file (assimp, HDF5, libmysofa): `read` returns a code below
// 100 for what it found, which is returned. A crash or a hang past 30 s stays in the child and
// becomes an InputError naming the file and `readers` ("the mesh reader (assimp)"); a child
// that cannot be made is std::runtime_error, an interrupt (Ctrl-C) as interrupt.hpp says.
int screen_file(const std::filesystem::path& file, const std::string& readers, const std::function<int()>& read);

// Bytes a run_isolated child hands to its parent: an anonymous memory file (memfd), made
// before the fork, that the child writes and the parent reads once the child has ended. Nothing
// on disk, and no pipe that fills while the parent only waits.
class ChildOutput {
 public:
  ChildOutput();  // throws std::runtime_error when no memory file can be made
  ~ChildOutput();
  ChildOutput(const ChildOutput&) = delete;
  ChildOutput& operator=(const ChildOutput&) = delete;
  // In the child: appends the bytes; false when they could not all be written.
  bool write(const void* data, std::size_t bytes);
  // In the parent: everything the child wrote.
  std::string read() const;

 private:
  int fd_ = -1;
};

// Whether `program` is an executable file in one of PATH's folders.
bool program_in_path(const std::string& program);

// A program fed through its stdin (ffmpeg reading raw video frames), without a shell; its
// stdout and stderr are captured. Not started: throws std::runtime_error. Destroyed before
// finish(): the program is killed (a failed run leaves no encoder behind).
class PipedProgram {
 public:
  explicit PipedProgram(const std::vector<std::string>& argv);
  ~PipedProgram();
  PipedProgram(const PipedProgram&) = delete;
  PipedProgram& operator=(const PipedProgram&) = delete;
  // False once the program has stopped reading (it exited or failed).
  bool write(const void* data, size_t bytes);
  // Closes its stdin and waits; the exit status (-1 when killed by a signal), `output` filled.
  int finish(std::string* output = nullptr);

 private:
  int pid_ = -1;
  int stdin_fd_ = -1;
  int output_fd_ = -1;
  std::string output_;
  std::thread reader_;  // drains stdout/stderr so the program never blocks on them
};

}  // namespace sonomap::harness
