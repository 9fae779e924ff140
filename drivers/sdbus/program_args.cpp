#include "drivers/sdbus/program_args.hpp"

#include <cstdio>
#include <cstdlib>

namespace caracara::dbus {

ProgramArgs::ProgramArgs(const char* program, const char* version, int argc, char** argv, std::function<void()> help)
    : program_(program), version_(version), argc_(argc), argv_(argv), help_(std::move(help)) {}

bool ProgramArgs::next(BusChoice& bus) {
    while (++at_ < argc_) {
        arg_ = argv_[at_];
        if (arg_ == "-h" || arg_ == "--help") {
            help_();
            std::exit(0);
        } else if (arg_ == "--version") {
            std::printf("%s %s\n", program_, version_);
            std::exit(0);
        } else if (arg_ == "--system") {
            bus = {BusChoice::Kind::System, {}};
        } else if (arg_ == "--user") {
            bus = {BusChoice::Kind::User, {}};
        } else if (is("--bus-address")) {
            bus = {BusChoice::Kind::Address, value()};
        } else {
            return true;
        }
    }
    return false;
}

bool ProgramArgs::is(std::string_view name) const {
    return arg_ == name || (arg_.size() > name.size() && arg_.starts_with(name) && arg_[name.size()] == '=');
}

std::string ProgramArgs::value() {
    const auto eq = arg_.find('=');
    const std::string name = arg_.substr(0, eq);
    std::string v;
    if (eq != std::string::npos)
        v = arg_.substr(eq + 1);
    else if (at_ + 1 < argc_)
        v = argv_[++at_];
    if (v.empty())
        usage_error(name + " needs a value");
    return v;
}

void ProgramArgs::unknown() const { usage_error("unknown option '" + arg_ + "'"); }

void ProgramArgs::usage_error(const std::string& message) const {
    std::fflush(stdout);
    std::fprintf(stderr, "%s: %s\nTry '%s --help'.\n", program_, message.c_str(), program_);
    std::exit(2);
}

} // namespace caracara::dbus
