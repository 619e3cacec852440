// SPDX-License-Identifier: GPL-3.0-or-later
// Every command's --help gives every option's default: an option that takes a value and is not
// required shows "=DEFAULT" after its type, or says in words what it defaults to, or is one of
// the optional inputs that have no default at all.
#include "cli_support.hpp"

#include <set>
#include <sstream>

using sonomap::test::run_sonomap;

namespace {

// The option entries of a help text: an entry starts with "  -" and runs on over the lines
// indented further (a wrapped description).
std::vector<std::string> option_entries(const std::string& help) {
  std::vector<std::string> entries;
  std::istringstream in(help);
  std::string line;
  bool in_options = false;
  while (std::getline(in, line)) {
    if (line.rfind("Options:", 0) == 0) in_options = true;
    else if (!line.empty() && line[0] != ' ') in_options = false;
    if (!in_options) continue;
    if (line.rfind("  -", 0) == 0) entries.push_back(line);
    else if (line.rfind("        ", 0) == 0 && !entries.empty()) entries.back() += " " + line;
  }
  return entries;
}

bool takes_value(const std::string& entry) {
  for (const char* type : {" TEXT", " FLOAT", " INT", " UINT", " ENUM"})
    if (entry.find(type) != std::string::npos) return true;
  return false;
}

// The option's name and type: the entry up to the two blanks before its description.
std::string head(const std::string& entry) {
  const std::size_t start = entry.find('-');
  const std::size_t end = entry.find("  ", start);
  return entry.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

}  // namespace

TEST_CASE("every command's --help shows the default of every option that has one", "[help]") {
  // Optional inputs with nothing to default to (the scenario's own seed is --seed's).
  const std::set<std::string> no_default = {"--circle", "--cylinder", "--command", "--junit", "--json", "--seed"};
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"run"}, {"compare"}, {"report"}, {"render"}, {"brir"}, {"sonify"},
        {"score"}, {"diff"}, {"keys"}, {"bench", "map"}, {"bench", "sonify"}, {"bench", "render"}}) {
    std::vector<std::string> args = command;
    args.push_back("--help");
    const auto help = run_sonomap(args);
    INFO(command.front() << (command.size() > 1 ? " " + command[1] : "") << " --help:\n" << help.output);
    REQUIRE(help.status == 0);
    const std::vector<std::string> entries = option_entries(help.output);
    CHECK(!entries.empty());  // at least --help: the entries were found
    for (const std::string& entry : entries) {
      if (!takes_value(entry) || entry.find("REQUIRED") != std::string::npos) continue;
      const std::string name_and_type = head(entry);
      const std::string name = name_and_type.substr(0, name_and_type.find(' '));
      const bool shown = name_and_type.find('=') != std::string::npos ||
                         entry.find("default") != std::string::npos ||
                         no_default.count(name.substr(name.rfind(',') + 1)) > 0;
      INFO(entry);
      CHECK(shown);
    }
  }
}
