// Logging to stderr with sd-daemon priority prefixes, which journald turns into priorities.
#pragma once

namespace caracara {

void log_error(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void log_warning(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void log_notice(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void log_info(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

} // namespace caracara
