// caracaractl's dive commands (docs/dive-format.md): they read the recorder's files directly,
// without the bus. `dives` lists them, `export` prints one as CSV, `plot` draws one with
// matplotlib (tools/caracaractl/plot_dive.py, run as a separate python3 process).
#pragma once

#include <string>
#include <vector>

namespace caracara::ctl {

// True for "dives", "export" and "plot".
bool is_dive_command(const std::string& name);
// Runs one of them with the arguments after its name; returns the exit status. Throws Failure.
int run_dive_command(const std::string& name, const std::vector<std::string>& args);
// Their part of --help.
const char* dive_help();

} // namespace caracara::ctl
