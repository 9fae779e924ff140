// Text output of caracaractl: values, the status report and the monitor's lines.
#pragma once

#include "tools/client/client.hpp"

#include <ostream>
#include <string>
#include <string_view>

namespace caracara::ctl {

using namespace caracara::client; // the vehicle's D-Bus client (tools/client)

// printf into a std::string.
std::string strf(const char* format, ...) __attribute__((format(printf, 1, 2)));

// A value on one line without spaces: 42, 3.1, true, ready, "", [1,2], (255,0,0).
std::string render(const Value& v);
// As render, with per-property units: Address/speed bytes in hex, Orientation in degrees.
std::string render_property(std::string_view name, const Value& v);

// "vehicle", "thruster/3", "teensy", "bus" for an object path of the daemon.
std::string object_label(std::string_view path);
// Local wall-clock time as HH:MM:SS.mmm.
std::string timestamp_now();

// The full human-readable report of `caracaractl status`.
void print_status(std::ostream& out, const Objects& objects);
// The monitor's first line: the key state of every object, after the timestamp.
std::string summary_line(const Objects& objects);

} // namespace caracara::ctl
