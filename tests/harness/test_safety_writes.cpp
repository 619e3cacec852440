// SPDX-License-Identifier: GPL-3.0-or-later
// A result is published whole or not at all: a failed write (full disk, file-size limit) is exit
// status 1 with the reason, a signal is exit 128 + signal, and neither leaves anything behind;
// staging folders of dead processes are swept by the next run.
#include "score_support.hpp"
#include "test_safety_support.hpp"

#include "harness/support/output.hpp"

#include <chrono>
#include <cstring>
#include <fstream>
#include <sys/mount.h>
#include <thread>

namespace fs = std::filesystem;
using namespace sonomap::test;

namespace {

const fs::path kSmoke = smoke_scene();

// A 256 KiB tmpfs at `dir` for the life of the object (mounted() false where not allowed).
class SmallDisk {
 public:
  explicit SmallDisk(const fs::path& dir) : dir_(dir) {
    fs::create_directories(dir_);
    mounted_ = ::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=256k") == 0;
    if (!mounted_) reason_ = std::strerror(errno);
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
  }
  bool mounted() const { return mounted_; }
  const std::string& reason() const { return reason_; }

 private:
  fs::path dir_;
  bool mounted_ = false;
  std::string reason_;
};

bool is_empty_dir(const fs::path& dir) { return fs::is_directory(dir) && fs::is_empty(dir); }

}  // namespace

TEST_CASE("a run on a full file system exits 1 with the reason and publishes nothing",
          "[safety]") {
  ScratchDir scratch("safety-full-disk");
  const fs::path disk = scratch.path() / "disk";
  SmallDisk small(disk);
  if (!small.mounted()) {
    WARN("skipped: cannot mount a small tmpfs here (" << small.reason()
                                                      << "); the file-size-limit test covers it");
    return;
  }
  // 12 frames of rasters (cylinder.csv: 12 x 360 x 19 rows) do not fit in 256 KiB.
  const auto result = run_sonomap(short_run(kSmoke, disk / "out", 12));
  INFO(result.output);
  CHECK(result.status == 1);
  CHECK(result.output.find("No space left on device") != std::string::npos);
  CHECK(is_empty_dir(disk));
}

TEST_CASE("a run whose writes fail (file-size limit, EFBIG) exits 1 and publishes nothing",
          "[safety]") {
  ScratchDir scratch("safety-fsize");
  const fs::path out = scratch.path() / "out", log = scratch.path().string() + ".log";
  const pid_t pid = start_sonomap(short_run(kSmoke, out, 12), log, 64 * 1024);
  const int status = wait_status(pid);
  const std::string output = text_of(log);
  fs::remove(log);
  INFO(output);
  CHECK(status == 1);
  CHECK(output.find("File too large") != std::string::npos);
  CHECK(is_empty_dir(scratch.path()));
}

TEST_CASE("SIGHUP, SIGTERM and SIGQUIT mid-run exit 128 + signal and leave no partial folder",
          "[safety]") {
  ScratchDir scratch("safety-signals");
  for (int signal : {SIGHUP, SIGTERM, SIGQUIT}) {
    const fs::path out = scratch.path() / ("out" + std::to_string(signal));
    const fs::path log = scratch.path() / ("log" + std::to_string(signal));
    const pid_t pid = start_sonomap(short_run(kSmoke, out, 3000), log);
    // Wait until the run has started writing (its staging folder exists), then signal it.
    fs::path staging = out;
    staging += ".partial-" + std::to_string(pid);
    for (int i = 0; i < 6000 && !fs::exists(staging); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    REQUIRE(fs::exists(staging));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    ::kill(pid, signal);
    const int status = wait_status(pid);
    INFO("signal " << signal << ": " << text_of(log));
    CHECK(status == 128 + signal);
    CHECK(!fs::exists(out));
    CHECK(!fs::exists(staging));
    fs::remove(log);
  }
  CHECK(partial_entries(scratch.path()).empty());
}

TEST_CASE("a stale staging folder of a dead process is removed by the next run, a user's "
          "folder of the same shape is not",
          "[safety]") {
  ScratchDir scratch("safety-stale");
  const std::string dead = std::to_string(dead_pid());
  const fs::path stale = scratch.path() / ("old.partial-" + dead);
  scratch.write("old.partial-" + dead + "/" + sonomap::harness::kResultMarker, "sonomap run 0\n");
  scratch.write("old.partial-" + dead + "/frames.csv", "frame\n");
  const fs::path users = scratch.write("photos.partial-" + dead + "/cat.jpg", "cat");
  const auto result = run_sonomap(short_run(kSmoke, scratch.path() / "out"));
  INFO(result.output);
  REQUIRE(result.status == 0);
  CHECK(!fs::exists(stale));
  CHECK(text_of(users) == "cat");
}

namespace {

// Whether process `pid` runs sonomap (it has exec'd: the test's own handlers, inherited by the
// fork, are gone) and has a handler installed for `signal` (the SigCgt mask of
// /proc/PID/status), i.e. it will stop cleanly rather than die of it.
bool catches(pid_t pid, int signal) {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/" + std::to_string(pid) + "/exe", ec);
  if (ec || exe != fs::canonical(std::getenv("SONOMAP_EXE"))) return false;
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (signal - 1)) & 1u;
  return false;
}

}  // namespace

TEST_CASE("SIGINT and SIGTERM while brir synthesises exit 128 + signal and publish nothing",
          "[safety][brir]") {
  ScratchDir scratch("safety-brir-signals");
  for (int signal : {SIGINT, SIGTERM}) {
    const fs::path out = scratch.path() / ("brirs" + std::to_string(signal));
    const fs::path log = scratch.path() / ("log" + std::to_string(signal));
    const pid_t pid = start_sonomap({"--quiet", "brir", "--out", out.string()}, log);
    // The handler goes in when the synthesis starts (the HRIRs are read by then).
    for (int i = 0; i < 6000 && !catches(pid, signal); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    REQUIRE(catches(pid, signal));
    ::kill(pid, signal);
    const int status = wait_status(pid);
    const std::string output = text_of(log);
    INFO("signal " << signal << ": " << output);
    CHECK(status == 128 + signal);
    CHECK(output.find("interrupted") != std::string::npos);  // stopped by sonomap, not killed
    CHECK(!fs::exists(out));
    fs::remove(log);
  }
  CHECK(partial_entries(scratch.path()).empty());
}

TEST_CASE("score whose writes fail (file-size limit) exits 1 with the reason and publishes nothing",
          "[safety][score]") {
  ScratchDir scratch("safety-score-fsize");
  const fs::path scene = scratch.write("square.yaml", square_room_scenario());
  std::vector<int> frames(20);
  for (int i = 0; i < 20; ++i) frames[i] = i;
  // 20 frames x 360 bins of circle.csv with truth (about 170 kB): well over the 64 KiB limit.
  const fs::path circle = scratch.write("circle.csv", constant_circle_csv(frames, 1.25));
  const fs::path out = scratch.path() / "out", log = scratch.path() / "score.log";
  const pid_t pid = start_sonomap({"--quiet", "score", scene.string(), "--circle", circle.string(), "--out",
                                   out.string(), "--frames", "20", "--pictures", "-1"},
                                  log, 64 * 1024);
  const int status = wait_status(pid);
  const std::string output = text_of(log);
  INFO(output);
  CHECK(status == 1);
  CHECK(output.find("File too large") != std::string::npos);
  CHECK(!fs::exists(out));
  CHECK(partial_entries(scratch.path()).empty());
}
