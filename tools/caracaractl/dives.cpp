#include "tools/caracaractl/dives.hpp"

#include "core/direction_judgement.hpp"
#include "core/dive_format.hpp"
#include "core/safety.hpp"
#include "drivers/platform/dive_files.hpp"
#include "drivers/protocol/seabotix.hpp"
#include "tools/caracaractl/mcap_export.hpp"
#include "tools/caracaractl/render.hpp"
#include "tools/client/client.hpp"
#include "tools/foxglove/dive_summary.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <optional>
#include <iostream>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace caracara::ctl {

using namespace caracara::client; // the vehicle's D-Bus client (tools/client)

namespace dive = caracara::dive;

namespace {

constexpr const char* kDefaultDir = "/var/log/caracara";
constexpr const char* kPython = "/usr/bin/python3";
#ifndef CARACARA_DATADIR
#define CARACARA_DATADIR "/usr/share"
#endif

struct DiveOptions {
    std::string dir = kDefaultDir;
    std::string out;
    bool events = false;
    bool partial = false;
    bool mcap = false;          // export --format mcap
    bool cdr = false;           // --encoding cdr: the ROS 2 topics for rosbag2 (docs/ros2.md)
    std::optional<caracara::ros::RangeLayout> distro; // --distro humble|jazzy: Range's layout, ROS_DISTRO
    std::optional<std::string> ros_config; // --ros-config FILE: caracara-ros's settings (namespace, frames)
    bool detection = false;     // plot --detection: one direction detection run (plot_detection.py)
    std::string wire;           // plot --detection --wire FILE: the simulator's orders, time_ns,thruster,speed
    std::string run = "-1";     // plot --detection --run N: which run of the dive (-1 the last)
    std::vector<std::string> positional;
};

[[noreturn]] void usage(const std::string& m) { throw Failure{kExitUsage, m}; }

DiveOptions parse(const std::string& name, const std::vector<std::string>& args) {
    DiveOptions o;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&](const char* opt) {
            if (i + 1 >= args.size())
                usage(std::string(opt) + " needs a value");
            return args[++i];
        };
        if (a == "--dir")
            o.dir = value("--dir");
        else if (a == "--out" && (name == "plot" || name == "export"))
            o.out = value("--out");
        else if (a == "--events" && name == "export")
            o.events = true;
        else if (a == "--detection" && name == "plot")
            o.detection = true;
        else if (a == "--wire" && name == "plot")
            o.wire = value("--wire");
        else if (a == "--run" && name == "plot") {
            o.run = value("--run");
            char* end = nullptr;
            (void)std::strtol(o.run.c_str(), &end, 10);
            if (o.run.empty() || *end != '\0')
                usage("--run takes a number, not '" + o.run + "'");
        }
        else if (a == "--format" && name == "export") {
            const std::string f = value("--format");
            if (f != "csv" && f != "mcap")
                usage("--format takes csv or mcap, not '" + f + "'");
            o.mcap = f == "mcap";
        }
        else if (a == "--encoding" && name == "export") {
            const std::string e = value("--encoding");
            if (e != "json" && e != "cdr")
                usage("--encoding takes json or cdr, not '" + e + "'");
            o.cdr = e == "cdr";
        }
        else if (a == "--distro" && name == "export") {
            const std::string d = value("--distro");
            o.distro = parse_name<caracara::ros::RangeLayout>(d);
            if (!o.distro)
                usage("--distro takes humble or jazzy, not '" + d + "'");
        }
        else if (a == "--ros-config" && name == "export")
            o.ros_config = value("--ros-config");
        else if (a == "--partial" && name != "dives")
            o.partial = true;
        else if (a.starts_with("--"))
            usage("unknown option '" + a + "' for " + name);
        else
            o.positional.push_back(a);
    }
    if (name == "export" && o.mcap && o.events)
        usage("--events applies to --format csv (in MCAP the events are the /events channel)");
    if (name == "export" && !o.mcap && o.cdr)
        usage("--encoding applies to --format mcap");
    if (name == "export" && o.distro && !o.cdr)
        usage("--distro applies to --format mcap --encoding cdr");
    if (name == "export" && o.ros_config && !o.cdr)
        usage("--ros-config applies to --format mcap --encoding cdr");
    if (name == "export" && !o.mcap && !o.out.empty())
        usage("--out applies to --format mcap");
    if (name == "plot" && !o.detection && (!o.wire.empty() || o.run != "-1"))
        usage("--wire and --run apply to plot --detection");
    const std::size_t want = name == "dives" ? 0 : 1;
    if (o.positional.size() != want)
        usage(strf("%s takes %zu argument%s, got %zu", name.c_str(), want, want == 1 ? "" : "s", o.positional.size()));
    return o;
}

// DIVE: a path, a file name in --dir, or "last" (the newest there).
std::string resolve(const DiveOptions& o) {
    const std::string& d = o.positional[0];
    if (d == "last") {
        std::string err;
        const auto files = caracara::list_dive_files(o.dir, &err);
        if (files.empty())
            throw Failure{kExitRefused, err.empty() ? "no dives in " + o.dir : err};
        return files.back().path;
    }
    struct stat st {};
    if (d.find('/') != std::string::npos || ::stat(d.c_str(), &st) == 0)
        return d;
    return o.dir + "/" + d;
}

// Reads and decodes; a file that cannot be read, or one with a problem (unless --partial and
// something came before it), ends caracaractl with status 1 and the problem named.
dive::Dive load(const std::string& path, bool partial) {
    std::vector<uint8_t> bytes;
    std::string err;
    if (!caracara::read_whole_file(path, bytes, err))
        throw Failure{kExitRefused, "cannot read dive " + err};
    dive::Dive d = dive::decode(bytes);
    if (!d.ok()) {
        const std::string what = path + ": " + d.message + " (" + std::to_string(d.samples.size()) +
                                 " samples before it)";
        if (!partial || d.samples.empty())
            throw Failure{kExitRefused, "bad dive file " + what + (d.samples.empty() ? "" : "; --partial uses them")};
        std::cerr << "caracaractl: warning: " << what << "; using what came before it\n";
    }
    return d;
}

double seconds(uint32_t t_100us) { return t_100us / 10000.0; }

std::string csv_text(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos)
        return s;
    std::string q = "\"";
    for (char c : s)
        q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
    return q + "\"";
}

std::string describe(const dive::Event& e) {
    using caracara::KillSource;
    using caracara::SafetyState;
    switch (e.kind) {
    case dive::EventKind::State: {
        std::string s = std::string(caracara::state_name(static_cast<SafetyState>(e.state)));
        if (static_cast<SafetyState>(e.state) == SafetyState::Killed)
            s += " source=" + std::string(caracara::kill_source_name(static_cast<KillSource>(e.kill_source)));
        if (!e.text.empty())
            s += " reason=" + e.text;
        return s;
    }
    case dive::EventKind::Fault:
        return strf("thruster=%u faults=%s", e.thruster, e.text.empty() ? "none" : e.text.c_str());
    case dive::EventKind::BusLost: return "reason=" + e.text;
    case dive::EventKind::BusRestored: return strf("pulses=%u ms=%.1f", e.value, e.number);
    case dive::EventKind::Profile: return strf("%s factor=%g", e.text.c_str(), e.number);
    case dive::EventKind::Failsafe:
        return strf("%s %s%s", e.text.c_str(), (e.value & dive::kFailsafeRaised) ? "raised" : "cleared",
                    (e.value & dive::kFailsafeVehicle) ? "" : strf(" thruster=%u", e.thruster).c_str());
    case dive::EventKind::MotorTest:
    case dive::EventKind::DetectionPulse:
        return (e.value & dive::kOn) ? strf("thruster=%u value=%.0f", e.thruster, e.number)
                                     : strf("thruster=%u stopped", e.thruster);
    case dive::EventKind::Detection:
        return (e.value & dive::kOn) ? std::string("started") : strf("ended judged=%.0f", e.number);
    case dive::EventKind::DetectionResult:
        return strf("thruster=%u verdict=%s margin=%.2f %s", e.thruster,
                    std::string(caracara::verdict_name(static_cast<caracara::DirectionVerdict>(e.value))).c_str(),
                    e.number, e.text.c_str());
    }
    return "";
}

void write_events(std::ostream& out, const dive::Dive& d) {
    out << "t_s,kind,detail,client\n";
    for (const dive::Event& e : d.events)
        out << strf("%.4f", seconds(e.t_100us)) << ',' << dive::event_kind_name(e.kind) << ',' << csv_text(describe(e))
            << ',' << csv_text(e.client) << '\n';
    if (d.ended)
        out << strf("%.4f", seconds(d.end.t_100us)) << ",end," << csv_text(d.end.reason) << ",\n";
}

void write_samples(std::ostream& out, const dive::Dive& d) {
    out << "t_s";
    for (const char* col : {"req", "app", "speed", "current_a", "temp_c", "faults", "nacks", "bad_replies", "errors"})
        for (std::size_t i = 0; i < dive::kThrusters; ++i)
            out << ',' << col << '_' << i;
    out << ",budget_limit,saturated,kill_switch,kill_output,teensy_online,bus_state,bus_errors,bus_recoveries"
           ",yaw,pitch,roll,distances_mm\n";
    for (const dive::Sample& s : d.samples) {
        out << strf("%.4f", seconds(s.t_100us));
        for (int16_t v : s.requested)
            out << ',' << v;
        for (int16_t v : s.applied)
            out << ',' << v;
        for (const auto& t : s.thrusters)
            out << ',' << (t.speed == dive::kUnknownSpeed ? std::string() : std::to_string(t.speed));
        for (const auto& t : s.thrusters)
            out << ',' << (t.flags & dive::kCurrentKnown ? strf("%.1f", t.current_da / 10.0) : std::string());
        for (const auto& t : s.thrusters)
            out << ',' << (t.flags & dive::kStatusKnown ? std::to_string(t.temperature_c) : std::string());
        for (const auto& t : s.thrusters)
            out << ',' << unsigned(t.faults);
        for (const auto& t : s.thrusters)
            out << ',' << t.nacks;
        for (const auto& t : s.thrusters)
            out << ',' << t.bad_replies;
        for (const auto& t : s.thrusters)
            out << ',' << t.errors;
        out << ',' << s.budget_limit << ',' << bool(s.flags & dive::kSaturated) << ','
            << bool(s.flags & dive::kKillSwitch) << ',' << bool(s.flags & dive::kKillOutput) << ','
            << bool(s.flags & dive::kTeensyOnline) << ',' << s.bus_state() << ',' << s.bus_errors << ','
            << s.bus_recoveries;
        for (float v : s.orientation)
            out << ',' << strf("%.4f", v);
        out << ',';
        for (std::size_t i = 0; i < s.distances.size(); ++i)
            out << (i ? " " : "") << s.distances[i];
        out << '\n';
    }
}

std::string local_time(uint64_t unix_ms) {
    const time_t t = static_cast<time_t>(unix_ms / 1000);
    tm lt{};
    ::localtime_r(&t, &lt);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &lt);
    return buf;
}

int cmd_dives(const DiveOptions& o) {
    std::string err;
    const auto dives = caracara::foxglove::summarize_dives(o.dir, &err);
    if (!err.empty())
        throw Failure{kExitRefused, "cannot list dives: " + err};
    std::cout << strf("%-34s %-19s %9s %8s %7s  %s\n", "DIVE", "START", "DURATION", "SAMPLES", "SIZE", "END");
    for (const auto& d : dives) {
        if (!d.read_error.empty()) {
            std::cout << strf("%-34s %s\n", d.file.name.c_str(), d.read_error.c_str());
            continue;
        }
        std::cout << strf("%-34s %-19s %8.1fs %8zu %6.0fK  %s\n", d.file.name.c_str(),
                          d.is_dive ? local_time(d.start_unix_ms).c_str() : "?", d.seconds, d.samples,
                          static_cast<double>(d.file.size) / 1024.0, d.end.c_str());
    }
    std::cout << strf("%zu dive%s in %s\n", dives.size(), dives.size() == 1 ? "" : "s", o.dir.c_str());
    return kExitOk;
}

int cmd_export(const DiveOptions& o) {
    const dive::Dive d = load(resolve(o), o.partial);
    if (o.mcap)
        return export_mcap(d, {o.out, o.cdr, o.distro, o.ros_config});
    if (o.events)
        write_events(std::cout, d);
    else
        write_samples(std::cout, d);
    return kExitOk;
}

// tools/caracaractl/plot_dive.py (or plot_detection.py): $CARACARA_PLOT_SCRIPT (plot_dive.py's),
// beside this program (a build tree), or installed.
std::string plot_script(const std::string& name) {
    if (const char* env = std::getenv("CARACARA_PLOT_SCRIPT"); env && *env && name == "plot_dive.py")
        return env;
    char self[4096];
    const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
    if (n > 0) {
        std::string dir(self, static_cast<std::size_t>(n));
        dir = dir.substr(0, dir.rfind('/'));
        if (::access((dir + "/" + name).c_str(), R_OK) == 0)
            return dir + "/" + name;
    }
    return std::string(CARACARA_DATADIR) + "/caracara/" + name;
}

int cmd_plot(const DiveOptions& o) {
    const std::string path = resolve(o);
    const dive::Dive d = load(path, o.partial);
    if (d.samples.empty())
        throw Failure{kExitRefused, path + ": the dive has no samples to plot"};
    std::string out = o.out;
    if (out.empty()) {
        std::string base = path.substr(path.rfind('/') + 1);
        if (base.ends_with(caracara::kDiveSuffix))
            base.resize(base.size() - std::strlen(caracara::kDiveSuffix));
        out = base + ".png";
    }
    if (!out.ends_with(".png") && !out.ends_with(".svg") && (o.detection || !out.ends_with(".html")))
        usage(std::string("--out must end in .png, .svg") + (o.detection ? "" : " or .html") + ", not '" + out + "'");
    char tmpl[] = "/tmp/caracara-plot.XXXXXX";
    if (!::mkdtemp(tmpl))
        throw Failure{kExitRefused, std::string("mkdtemp: ") + std::strerror(errno)};
    const std::string tmp = tmpl;
    {
        std::ofstream s(tmp + "/samples.csv"), e(tmp + "/events.csv");
        write_samples(s, d);
        write_events(e, d);
    }
    const std::string script = plot_script(o.detection ? "plot_detection.py" : "plot_dive.py");
    const std::string title = path.substr(path.rfind('/') + 1) + "  (" + local_time(d.header.start_unix_ms) +
                              (o.detection ? ", direction detection" : ", ended: " + caracara::foxglove::dive_end(d)) + ")";
    std::vector<std::string> argv = {kPython, script, "--samples", tmp + "/samples.csv", "--events", tmp + "/events.csv",
                                     "--title", title, "--out", out};
    if (o.detection) {
        // The dive's start on CLOCK_MONOTONIC: where the simulator's wire log meets the dive's times.
        argv.insert(argv.end(), {"--start-mono-ns", std::to_string(d.header.start_mono_ns), "--run", o.run});
        if (!o.wire.empty())
            argv.insert(argv.end(), {"--wire", o.wire});
    }
    std::vector<char*> cargv;
    for (std::string& a : argv)
        cargv.push_back(a.data());
    cargv.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        // Debian's interpreter, the one python3-matplotlib is installed for (not a python3
        // that happens to come first in PATH).
        ::execv(kPython, cargv.data());
        std::fprintf(stderr, "caracaractl: cannot run %s: %s\n", kPython, std::strerror(errno));
        ::_exit(127);
    }
    int status = 0;
    if (pid > 0)
        ::waitpid(pid, &status, 0);
    std::remove((tmp + "/samples.csv").c_str());
    std::remove((tmp + "/events.csv").c_str());
    ::rmdir(tmp.c_str());
    if (pid < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw Failure{kExitRefused, "plotting failed (" + script + "; it needs python3-matplotlib)"};
    std::cout << out << '\n';
    return kExitOk;
}

} // namespace

bool is_dive_command(const std::string& name) { return name == "dives" || name == "export" || name == "plot"; }

int run_dive_command(const std::string& name, const std::vector<std::string>& args) {
    const DiveOptions o = parse(name, args);
    if (name == "dives")
        return cmd_dives(o);
    if (name == "export")
        return cmd_export(o);
    return cmd_plot(o);
}

const char* dive_help() {
    return "\nDive recordings (read from the recorder's directory, no bus needed):\n"
           "  dives [--dir DIR]                List the dives in DIR (default /var/log/caracara)\n"
           "  plot DIVE [--out FILE] [--dir DIR] [--partial]\n"
           "                                   Plot motor values, currents, temperatures and\n"
           "                                   orientation with kills, faults and bus recoveries\n"
           "                                   marked; FILE ends in .png (default), .svg or .html\n"
           "  plot DIVE --detection [--wire FILE] [--run N] [--out FILE]\n"
           "                                   Plot one direction detection run (the last, or run\n"
           "                                   N from 0): each thruster's pulse and the attitude\n"
           "                                   change it caused, with its verdict; --wire adds the\n"
           "                                   simulator's orders (CSV time_ns,thruster,speed)\n"
           "  export DIVE [--events] [--dir DIR] [--partial]\n"
           "                                   Print the samples (or the events) as CSV\n"
           "  export DIVE --format mcap [--out FILE] [--dir DIR] [--partial]\n"
           "                                   Write the dive as MCAP on the channels of\n"
           "                                   caracara-bridge, for Foxglove (docs/foxglove.md)\n"
           "  export DIVE --format mcap --encoding cdr [--distro humble|jazzy] [--ros-config FILE]\n"
           "         [--out FILE] [--dir DIR] [--partial]\n"
           "                                   Write it as caracara-ros's ROS 2 topics (CDR, ros2msg\n"
           "                                   schemas, each with the QoS caracara-ros offers) for\n"
           "                                   rosbag2: ros2 bag play (docs/ros2.md); --distro: Range's\n"
           "                                   layout and the bag's ROS_DISTRO (default humble);\n"
           "                                   namespace and frames from caracara-ros's settings\n"
           "                                   (--ros-config, default /etc/caracara/ros.toml if there)\n"
           "  DIVE is a path, a file name in DIR, or \"last\". A truncated or corrupt file is refused\n"
           "  (status 1, the problem and its byte offset named); --partial uses what came before it.\n";
}

} // namespace caracara::ctl
