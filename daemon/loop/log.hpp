// Logging to stderr with sd-daemon priority prefixes, which journald turns into priorities.
#pragma once

#include <cstddef>
#include <string_view>

namespace caracara {

void log_error(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void log_warning(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void log_notice(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void log_info(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
// A thruster fault bit that appeared or cleared, once per change: under journald with the
// fields THRUSTER= and FAULT= (journalctl THRUSTER=3), else as a plain line on stderr.
void log_thruster_fault(size_t thruster, std::string_view fault, bool appeared);

} // namespace caracara
