// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/compare.hpp"

#include "harness/report/report.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/interrupt.hpp"
#include "harness/support/output.hpp"
#include "harness/support/progress.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fcntl.h>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

extern char** environ;
namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

// Reads one YAML mapping with a fixed set of keys; every error names file, line and key.
class SweepReader {
 public:
  explicit SweepReader(fs::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& key, const std::string& what) const {
    throw InputError(file_.string(), node.Mark().line >= 0 ? node.Mark().line + 1 : 0, key, what);
  }

  void check_keys(const YAML::Node& map, const std::string& where,
                  const std::set<std::string>& allowed) const {
    if (!map.IsMap()) fail(map, where, "expected a mapping");
    for (const auto& kv : map) {
      const std::string key = kv.first.as<std::string>();
      if (!allowed.count(key)) {
        std::string names;
        for (const auto& a : allowed) names += (names.empty() ? "" : ", ") + a;
        fail(kv.first, where.empty() ? key : where + "." + key, "unknown key (allowed: " + names + ")");
      }
    }
  }

  template <typename T>
  T scalar(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, key, "expected a single value");
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      fail(node, key, "cannot read '" + node.Scalar() + "' as the expected type");
    }
  }

  std::vector<std::string> strings(const YAML::Node& node, const std::string& key) const {
    if (!node) return {};
    if (!node.IsSequence()) fail(node, key, "expected a list");
    std::vector<std::string> out;
    for (std::size_t i = 0; i < node.size(); ++i)
      out.push_back(scalar<std::string>(node[i], key + "[" + std::to_string(i) + "]"));
    return out;
  }

  std::string identifier(const YAML::Node& node, const std::string& key) const {
    const std::string id = scalar<std::string>(node, key);
    const bool ok = !id.empty() && std::all_of(id.begin(), id.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.';
    });
    if (!ok) fail(node, key, "'" + id + "' must be letters, digits, '_' or '.' (it names directories)");
    return id;
  }

 private:
  fs::path file_;
};

std::string shell_quote(const std::string& s) {
  if (!s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || std::string("-_./=,:+").find(c) != std::string::npos;
      }))
    return s;
  std::string out = "'";
  for (char c : s) out += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

void append_frames_list(std::vector<std::string>& args, const char* option,
                        const std::vector<std::string>& frames) {
  if (frames.empty()) return;
  args.push_back(option);
  for (const auto& f : frames) args.push_back(f);
}

// The `claims` or `gates` list: each names a scenario and a variant of this sweep. A gate has
// no paper figure or note, and its text defaults to its check.
std::vector<Claim> read_sweep_claims(const SweepReader& r, const YAML::Node& root, const Sweep& sweep,
                                     const std::string& list_name) {
  const bool gates = list_name == "gates";
  std::vector<Claim> claims;
  const YAML::Node list = root[list_name];
  if (!list) return claims;
  if (!list.IsSequence()) r.fail(list, list_name, "expected a list");
  std::set<std::string> scenarios, variants;
  for (const auto& s : root["scenarios"]) scenarios.insert(s["id"].as<std::string>());
  for (const auto& v : root["variants"]) variants.insert(v["id"].as<std::string>());
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node c = list[i];
    const std::string key = list_name + "[" + std::to_string(i) + "]";
    if (gates) r.check_keys(c, key, {"text", "scenario", "variant", "metric", "op", "value", "versus"});
    else r.check_keys(c, key, {"text", "scenario", "variant", "metric", "op", "value", "versus", "paper", "note"});
    for (const char* required : {"text", "scenario", "variant", "metric", "op", "value"})
      if (!c[required] && !(gates && std::string(required) == "text")) r.fail(c, key + "." + required, "missing");
    Claim claim;
    if (c["text"]) claim.text = r.scalar<std::string>(c["text"], key + ".text");
    claim.scenario = r.scalar<std::string>(c["scenario"], key + ".scenario");
    if (!scenarios.count(claim.scenario))
      r.fail(c["scenario"], key + ".scenario", "no scenario '" + claim.scenario + "' in " + sweep.name);
    claim.variant = r.scalar<std::string>(c["variant"], key + ".variant");
    if (!variants.count(claim.variant))
      r.fail(c["variant"], key + ".variant", "no variant '" + claim.variant + "' in " + sweep.name);
    claim.metric = r.identifier(c["metric"], key + ".metric");
    claim.op = r.scalar<std::string>(c["op"], key + ".op");
    if (!is_claim_operator(claim.op)) r.fail(c["op"], key + ".op", "expected >=, <=, > or <");
    claim.value = r.scalar<double>(c["value"], key + ".value");
    if (!std::isfinite(claim.value)) r.fail(c["value"], key + ".value", "must be finite");
    if (c["versus"]) {
      claim.versus = r.scalar<std::string>(c["versus"], key + ".versus");
      if (!variants.count(claim.versus))
        r.fail(c["versus"], key + ".versus", "no variant '" + claim.versus + "' in " + sweep.name);
    }
    if (claim.text.empty())
      claim.text = fmt::format("{} {} {}{}", claim.metric, claim.op, claim.value,
                               claim.versus.empty() ? "" : " x " + claim.versus);
    if (c["paper"]) claim.paper = r.scalar<std::string>(c["paper"], key + ".paper");
    if (c["note"]) claim.note = r.scalar<std::string>(c["note"], key + ".note");
    claims.push_back(std::move(claim));
  }
  return claims;
}

// An external mapper's variant runs `sonomap score --command`; it has no voxel or pictures of
// a map (score draws the rasters it is given).
void append_command_variant(const SweepReader& r, const YAML::Node& v, const std::string& vkey,
                            const fs::path& out, std::vector<std::string>& args) {
  if (v["voxel"]) r.fail(v["voxel"], vkey + ".voxel", "an external command has no voxel size (give it in its command)");
  const std::string command = r.scalar<std::string>(v["command"], vkey + ".command");
  if (command.find_first_not_of(" \t") == std::string::npos) r.fail(v["command"], vkey + ".command", "is empty");
  double timeout = 600.0;
  if (v["timeout"]) {
    timeout = r.scalar<double>(v["timeout"], vkey + ".timeout");
    if (!(timeout > 0.0 && timeout <= 7 * 86400.0)) r.fail(v["timeout"], vkey + ".timeout", "must be in (0, 604800] seconds");
  }
  args.insert(args.end(), {"--name", r.scalar<std::string>(v["id"], vkey + ".id"), "--command", command,
                           "--timeout", fmt::format("{}", timeout), "--sequence-cache", (out / "sequences").string()});
}

YAML::Node load_sweep_yaml(const fs::path& file) {
  try {
    return YAML::LoadFile(file.string());
  } catch (const YAML::BadFile&) {
    throw InputError(file.string() + ": cannot open the sweep file");
  } catch (const YAML::ParserException& e) {
    throw InputError(file.string(), e.mark.line + 1, "", "malformed YAML: " + e.msg);
  }
}

int positive(const SweepReader& r, const YAML::Node& node, const std::string& key) {
  const int v = r.scalar<int>(node, key);
  if (v < 1) r.fail(node, key, "must be at least 1");
  return v;
}

// What a sweep's jobs share (the file's top level), or one scenario entry of it.
struct JobBase {
  fs::path scenario_file;
  std::string scenario_id;
  int frames = 0, every = 0;  // 0: the scenario's own
  std::vector<std::string> set, pictures, sweeps;
  std::vector<std::uint64_t> seeds{1};
  bool listen = false;  // each run writes listen.wav (the same walk per scenario: A/B by ear)
};

JobBase read_top_level(const SweepReader& r, const YAML::Node& root) {
  JobBase top;
  top.set = r.strings(root["set"], "set");
  top.pictures = r.strings(root["pictures"], "pictures");
  top.sweeps = r.strings(root["sweeps"], "sweeps");
  top.listen = root["listen"] && r.scalar<bool>(root["listen"], "listen");
  if (root["seeds"]) {
    if (!root["seeds"].IsSequence() || root["seeds"].size() == 0) r.fail(root["seeds"], "seeds", "expected a non-empty list");
    top.seeds.clear();
    for (std::size_t i = 0; i < root["seeds"].size(); ++i)
      top.seeds.push_back(r.scalar<std::uint64_t>(root["seeds"][i], "seeds[" + std::to_string(i) + "]"));
  }
  if (root["frames"]) top.frames = positive(r, root["frames"], "frames");
  if (root["every"]) top.every = positive(r, root["every"], "every");
  for (const char* list : {"scenarios", "variants"})
    if (!root[list] || !root[list].IsSequence() || root[list].size() == 0)
      r.fail(root[list] ? root[list] : root, list, "expected a non-empty list");
  return top;
}

// scenarios[si]: its id, file and the settings it overrides, on top of the top level's.
JobBase read_scenario_entry(const SweepReader& r, const YAML::Node& s, const std::string& skey,
                            const fs::path& base, const JobBase& top) {
  r.check_keys(s, skey, {"id", "file", "frames", "every", "set"});
  if (!s["id"] || !s["file"]) r.fail(s, skey, "needs id and file");
  JobBase sc = top;
  sc.scenario_id = r.identifier(s["id"], skey + ".id");
  sc.scenario_file = base / r.scalar<std::string>(s["file"], skey + ".file");
  if (!fs::is_regular_file(sc.scenario_file))
    r.fail(s["file"], skey + ".file", "no such file: " + sc.scenario_file.string());
  if (s["frames"]) sc.frames = positive(r, s["frames"], skey + ".frames");
  if (s["every"]) sc.every = positive(r, s["every"], skey + ".every");
  sc.set = r.strings(s["set"], skey + ".set");
  return sc;
}

// The command line of one run: the scenario entry `sc`, variant `v`, one seed.
std::vector<std::string> job_args(const SweepReader& r, const JobBase& top, const JobBase& sc, const YAML::Node& v,
                                  const std::string& vkey, std::uint64_t seed, const std::string& sweep_name,
                                  const fs::path& run_dir, const fs::path& out) {
  const std::string vid = v["id"].as<std::string>();
  // An external command evaluates the frames it chooses, has no built-in mapper to set up
  // (mapper.* keys are for those) and makes no sweeps.
  const bool external = static_cast<bool>(v["command"]);
  std::vector<std::string> a = {"--quiet", external ? "score" : "run", sc.scenario_file.string(), "--out",
                                run_dir.string(), "--seed", std::to_string(seed), "--tag", "scenario=" + sc.scenario_id,
                                "--tag", "variant=" + vid, "--tag", "sweep=" + sweep_name};
  if (external) append_command_variant(r, v, vkey, out, a);
  else a.insert(a.end(), {"--mapper", r.scalar<std::string>(v["mapper"], vkey + ".mapper")});
  if (v["voxel"]) {
    const double voxel = r.scalar<double>(v["voxel"], vkey + ".voxel");
    if (!(voxel > 0)) r.fail(v["voxel"], vkey + ".voxel", "must be positive");
    a.insert(a.end(), {"--voxel", fmt::format("{}", voxel)});
  }
  if (sc.frames > 0) a.insert(a.end(), {"--frames", std::to_string(sc.frames)});
  if (sc.every > 0 && !external) a.insert(a.end(), {"--every", std::to_string(sc.every)});
  for (const auto& lists : {top.set, sc.set, r.strings(v["set"], vkey + ".set")})
    for (const auto& o : lists)
      if (!external || o.rfind("mapper.", 0) != 0) a.insert(a.end(), {"--set", o});
  append_frames_list(a, "--pictures", top.pictures);
  if (!external) append_frames_list(a, "--sweeps", top.sweeps);
  if (top.listen && !external) a.push_back("--listen");
  return a;
}

}  // namespace

Sweep load_sweep(const fs::path& file, const fs::path& out) {
  const YAML::Node root = load_sweep_yaml(file);
  SweepReader r(file);
  r.check_keys(root, "", {"name", "frames", "every", "seeds", "set", "scenarios", "variants",
                          "pictures", "sweeps", "listen", "description", "claims", "gates"});
  Sweep sweep;
  if (!root["name"]) r.fail(root, "name", "missing");
  sweep.name = r.identifier(root["name"], "name");
  const JobBase top = read_top_level(r, root);
  std::set<std::string> ids;
  for (std::size_t si = 0; si < root["scenarios"].size(); ++si) {
    const std::string skey = "scenarios[" + std::to_string(si) + "]";
    const JobBase sc = read_scenario_entry(r, root["scenarios"][si], skey, file.parent_path(), top);
    for (std::size_t vi = 0; vi < root["variants"].size(); ++vi) {
      const YAML::Node v = root["variants"][vi];
      const std::string vkey = "variants[" + std::to_string(vi) + "]";
      r.check_keys(v, vkey, {"id", "mapper", "voxel", "set", "command", "timeout"});
      if (!v["id"] || !v["mapper"] == !v["command"]) r.fail(v, vkey, "needs id and either mapper or command");
      const std::string vid = r.identifier(v["id"], vkey + ".id");
      for (std::uint64_t seed : top.seeds) {
        Job job;
        job.id = fmt::format("{}-{}-s{}", sc.scenario_id, vid, seed);
        if (!ids.insert(job.id).second) r.fail(v["id"], vkey + ".id", "duplicate run id " + job.id);
        job.args = job_args(r, top, sc, v, vkey, seed, sweep.name, out / "runs" / job.id, out);
        sweep.jobs.push_back(std::move(job));
      }
    }
  }
  sweep.claims = read_sweep_claims(r, root, sweep, "claims");
  sweep.gates = read_sweep_claims(r, root, sweep, "gates");
  return sweep;
}

std::string job_list(const Sweep& sweep, const std::string& program) {
  std::string text;
  for (const Job& job : sweep.jobs) {
    text += shell_quote(program);
    for (const auto& a : job.args) text += " " + shell_quote(a);
    text += "\n";
  }
  return text;
}

namespace {

// The sonomap binary itself, so every job runs the same code as the parent.
std::string self_program() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("sonomap") : self.string();
}

pid_t spawn_job(const std::string& program, const Job& job, int threads, const fs::path& log) {
  std::vector<std::string> argv{program};
  if (threads > 0) argv.insert(argv.end(), {"--threads", std::to_string(threads)});
  argv.insert(argv.end(), job.args.begin(), job.args.end());
  std::vector<char*> cargs;
  for (auto& a : argv) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, program.c_str(), &actions, nullptr, cargs.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

struct CompareOptions {
  fs::path sweep_file;
  fs::path out;
  int jobs = 1;
  bool emit_jobs = false;
  bool rerun = false;
  fs::path junit;  // empty: no JUnit XML
};

int run_compare(const CompareOptions& o, const GlobalOptions& global) {
  const Sweep sweep = load_sweep(o.sweep_file, o.out);
  const std::string program = self_program();
  prepare_output_directory(o.out, "compare", {o.sweep_file});
  // `report` reads claims and gates from here, whoever runs the jobs.
  // A sweep edited to have none removes the earlier file (compare wrote it).
  for (const auto& [file, checks] : {std::pair{"claims.json", &sweep.claims}, std::pair{"gates.json", &sweep.gates}}) {
    if (checks->empty()) {
      fs::remove(o.out / file);
      continue;
    }
    write_text_file(o.out / file, claims_to_json(*checks).dump(2) + "\n");
  }
  if (o.emit_jobs) {
    std::fputs(job_list(sweep, program).c_str(), stdout);
    return 0;
  }
  fs::create_directories(o.out / "runs");
  fs::create_directories(o.out / "logs");
  // Resume: a run directory exists only once complete (it is renamed into place at the end).
  std::vector<const Job*> todo;
  int skipped = 0;
  for (const Job& job : sweep.jobs) {
    if (!o.rerun && fs::exists(o.out / "runs" / job.id / "summary.json")) ++skipped;
    else todo.push_back(&job);
  }
  if (!global.quiet)
    std::fprintf(stderr, "compare %s: %zu runs (%d finished before, %zu to run, %d at a time)\n",
                 sweep.name.c_str(), sweep.jobs.size(), skipped, todo.size(), o.jobs);
  // Split the cores between concurrent runs unless the user chose.
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = global.threads > 0 ? global.threads : std::max(1, cores / o.jobs);

  install_interrupt_handler();
  std::map<pid_t, const Job*> running;
  std::vector<std::string> failed;
  std::size_t next = 0, done = 0;
  Progress progress("compare " + sweep.name, static_cast<long>(todo.size()), global.quiet);
  while ((next < todo.size() && !interrupt_requested()) || !running.empty()) {
    while (!interrupt_requested() && next < todo.size() && static_cast<int>(running.size()) < o.jobs) {
      const Job* job = todo[next++];
      const pid_t pid = spawn_job(program, *job, threads, o.out / "logs" / (job->id + ".log"));
      if (pid < 0) failed.push_back(job->id + " (could not start)");
      else running[pid] = job;
    }
    if (running.empty()) continue;
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) {
        // Forward the interrupt so each run removes its partial directory.
        for (const auto& entry : running) ::kill(entry.first, interrupt_signal());
        continue;
      }
      break;
    }
    auto it = running.find(pid);
    if (it == running.end()) continue;
    const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (!ok && !interrupt_requested())
      failed.push_back(it->second->id + " (see logs/" + it->second->id + ".log)");
    running.erase(it);
    progress.update(static_cast<long>(++done));
  }
  progress.finish();
  if (interrupt_requested()) {
    std::fprintf(stderr, "compare: interrupted; finished runs are kept, rerun to resume\n");
    return interrupt_exit_status();
  }
  for (const auto& f : failed) std::fprintf(stderr, "compare: run failed: %s\n", f.c_str());
  const ReportOutcome report = build_report(o.out, global.quiet, o.junit);
  return failed.empty() && report.failed_gates == 0 ? 0 : kExitFailure;
}

}  // namespace

void add_compare_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Run every combination of a sweep file (scenarios x variants x seeds), each an "
                 "independent run, then roll them up into a report");
  cmd->add_option("sweep", o->sweep_file, "Sweep file (YAML)")->required();
  cmd->add_option("--out", o->out,
                  "Output directory (runs/, logs/, rollup.csv, report.md): new, empty, or an "
                  "earlier compare result (resumed)")
      ->required();
  cmd->add_option("-j,--jobs", o->jobs, "Runs at the same time")->check(CLI::PositiveNumber);
  cmd->add_flag("--emit-jobs", o->emit_jobs,
                "Print one command per run (for GNU parallel or a Slurm array) and exit; "
                "then `sonomap report DIR` rolls up");
  cmd->add_flag("--rerun", o->rerun, "Run again even the runs that finished before");
  cmd->add_option("--junit", o->junit, "Also write JUnit XML: one test case per gate and claim");
  cmd->callback([o, &global] {
    const int status = run_compare(*o, global);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace sonomap::harness
