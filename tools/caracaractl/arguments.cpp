#include "tools/caracaractl/arguments.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace caracara::ctl {

namespace {

// The longest --for: beyond any dive, and far from overflowing the microsecond clock.
constexpr double kMaxHoldSeconds = 1e9;

template <typename T>
T parse_number(const std::string& text, const std::string& what) {
    const char* begin = text.data();
    const char* end = begin + text.size();
    if (text.size() > 1 && text[0] == '+' && text[1] != '-')
        ++begin; // from_chars takes no '+'
    T value{};
    const auto [stop, ec] = std::from_chars(begin, end, value);
    if (text.empty() || ec == std::errc::invalid_argument || stop != end)
        usage_error(what + " must be a number, not '" + text + "'");
    if (ec == std::errc::result_out_of_range)
        usage_error(what + " '" + text + "' is out of range");
    return value;
}

} // namespace

void usage_error(const std::string& message) { throw Failure{kExitUsage, message}; }

int32_t parse_int(const std::string& text, const std::string& what) { return parse_number<int32_t>(text, what); }
double parse_double(const std::string& text, const std::string& what) { return parse_number<double>(text, what); }

uint8_t parse_byte(const std::string& text, const std::string& what) {
    const int32_t v = parse_number<int32_t>(text, what);
    if (v < 0 || v > 255)
        usage_error(what + " must be 0..255, not '" + text + "'");
    return static_cast<uint8_t>(v);
}

std::vector<int32_t> parse_ints(const Args& args, const char* what) {
    std::vector<int32_t> out;
    for (size_t i = 0; i < args.size(); ++i)
        out.push_back(parse_int(args[i], std::string(what) + " " + std::to_string(i)));
    return out;
}

uint64_t parse_duration(const std::string& text) {
    const double seconds = parse_double(text, "--for");
    if (!std::isfinite(seconds) || seconds <= 0 || seconds > kMaxHoldSeconds)
        usage_error("--for needs a positive number of seconds, not '" + text + "'");
    return std::max<uint64_t>(1, static_cast<uint64_t>(std::llround(seconds * 1e6)));
}

Client::Appender int_array(std::vector<int32_t> values) {
    return [values = std::move(values)](sd_bus_message* m) {
        return sd_bus_message_append_array(m, 'i', values.data(), values.size() * sizeof(int32_t));
    };
}

std::string int_list(const std::vector<int32_t>& values) {
    std::string out = "[";
    for (size_t i = 0; i < values.size(); ++i)
        out += (i ? "," : "") + std::to_string(values[i]);
    return out + "]";
}

} // namespace caracara::ctl
