// caracaractl's strict argument parsing: a command's values are parsed completely before anything
// is sent, and only the D-Bus wire types are checked here (value ranges are the daemon's business).
// A bad value throws Failure{kExitUsage} naming the argument.
#pragma once

#include "tools/client/client.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace caracara::ctl {

using namespace caracara::client; // the vehicle's D-Bus client (tools/client)

// A command's values, after its name, without the command options.
using Args = std::vector<std::string>;

// Throws Failure{kExitUsage, message}: exit 2, nothing sent.
[[noreturn]] void usage_error(const std::string& message);

// A whole decimal number (a leading '+' allowed), else a usage error naming `what`.
int32_t parse_int(const std::string& text, const std::string& what);
double parse_double(const std::string& text, const std::string& what);
// D-Bus type 'y': the wire cannot carry anything outside 0..255.
uint8_t parse_byte(const std::string& text, const std::string& what);
// Each of args as an int, named "<what> <index>" in an error.
std::vector<int32_t> parse_ints(const Args& args, const char* what);
// --for SECONDS: positive, finite, decimals allowed; in microseconds.
uint64_t parse_duration(const std::string& text);

// Appends values as D-Bus type 'ai'.
Client::Appender int_array(std::vector<int32_t> values);
// "[1000,0,-500]" for the holding line.
std::string int_list(const std::vector<int32_t>& values);

} // namespace caracara::ctl
