#include "tests/integration/sim_fixture.hpp"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdarg>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace caracara::test {

using namespace std::chrono_literals;

std::string bin(const char* name) { return std::string(CARACARA_BUILD_DIR) + "/" + name; }

namespace {
// A cross build's programs are foreign binaries: the tests start them through the emulator
// ctest runs the tests with (CARACARA_TEST_EMULATOR, words separated by spaces; set by
// tests/CMakeLists.txt from CMAKE_CROSSCOMPILING_EMULATOR). Other programs run natively.
std::vector<std::string> with_emulator(const std::vector<std::string>& argv) {
    const char* emu = std::getenv("CARACARA_TEST_EMULATOR");
    if (!emu || !*emu || argv.empty() || argv[0].rfind(std::string(CARACARA_BUILD_DIR) + "/", 0) != 0)
        return argv;
    std::vector<std::string> out;
    std::istringstream words(emu);
    for (std::string w; words >> w;)
        out.push_back(w);
    out.insert(out.end(), argv.begin(), argv.end());
    return out;
}
} // namespace

void Process::start(const std::vector<std::string>& command, const std::string& log_path) {
    const std::vector<std::string> argv = with_emulator(command);
    pid_ = fork();
    if (pid_ < 0)
        throw std::runtime_error("fork failed");
    if (pid_ == 0) {
        int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        sigset_t none;
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, nullptr);
        std::vector<char*> args;
        for (auto& a : argv)
            args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        execvp(args[0], args.data());
        _exit(127);
    }
}

bool Process::running() {
    if (pid_ <= 0)
        return false;
    int st = 0;
    pid_t r = waitpid(pid_, &st, WNOHANG);
    if (r == pid_) {
        pid_ = -1;
        return false;
    }
    return true;
}

int Process::wait_exit(int timeout_ms) {
    if (pid_ <= 0)
        return -1;
    for (int waited = 0; waited <= timeout_ms; waited += 10) {
        int st = 0;
        if (waitpid(pid_, &st, WNOHANG) == pid_) {
            pid_ = -1;
            return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
        }
        std::this_thread::sleep_for(10ms);
    }
    return -1;
}

int Process::terminate() {
    if (pid_ <= 0)
        return -1;
    kill(pid_, SIGTERM);
    int st = wait_exit(10000);
    if (st < 0)
        stop(SIGKILL);
    return st;
}

void Process::stop(int sig) {
    if (pid_ <= 0)
        return;
    kill(pid_, sig);
    if (wait_exit(5000) < 0 && pid_ > 0) {
        kill(pid_, SIGKILL);
        waitpid(pid_, nullptr, 0);
        pid_ = -1;
    }
}

std::string read_file(const std::string& path) {
    std::ifstream in(path);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string start_private_bus(Process& daemon, const std::string& dir, const std::string& name) {
    const std::string path = dir + "/" + name;
    const std::string address = "unix:path=" + path;
    // An open policy: the tests are its only users.
    {
        std::ofstream conf(path + ".conf");
        conf << "<!DOCTYPE busconfig PUBLIC \"-//freedesktop//DTD D-Bus Bus Configuration 1.0//EN\"\n"
                " \"http://www.freedesktop.org/standards/dbus/1.0/busconfig.dtd\">\n"
                "<busconfig><type>session</type><listen>" + address + "</listen>"
                "<auth>EXTERNAL</auth><policy context=\"default\"><allow send_destination=\"*\" eavesdrop=\"true\"/>"
                "<allow eavesdrop=\"true\"/><allow own=\"*\"/></policy></busconfig>\n";
    }
    // The socket file appears at bind(), before listen(): a connect in between is refused.
    // dbus-daemon prints its address (into its log) only once it listens.
    const std::string log_path = path + "-dbus.log";
    daemon.start({"/usr/bin/dbus-daemon", "--nofork", "--print-address=1", "--config-file=" + path + ".conf"}, log_path);
    for (int i = 0;; ++i) {
        if (read_file(log_path).find(address) != std::string::npos)
            return address;
        if (i == 3000 || !daemon.running())
            throw std::runtime_error("the private dbus-daemon did not come up; see " + log_path);
        std::this_thread::sleep_for(10ms);
    }
}

SimFixture::SimFixture(const std::vector<std::string>& sim_args) {
    char tmpl[] = "/tmp/caracara-test-XXXXXX";
    if (!mkdtemp(tmpl))
        throw std::runtime_error("mkdtemp failed");
    dir_ = tmpl;
    socket_ = dir_ + "/sim.sock";
    start_private_bus(dbus_daemon, dir_, "bus");

    std::vector<std::string> argv = {bin("sim/caracara-sim"), "--socket", socket_, "--bus-address", bus_address()};
    argv.insert(argv.end(), sim_args.begin(), sim_args.end());
    sim.start(argv, dir_ + "/sim.log");

    dbus::BusChoice choice{dbus::BusChoice::Kind::Address, bus_address()};
    int r = dbus::open_bus(choice, "caracara-test", bus_);
    if (r < 0)
        throw std::runtime_error("cannot connect to the private bus: " + std::string(strerror(-r)));
    // Ready when the simulator owns its name (it listens on the socket before that).
    for (int i = 0; i < 500; ++i) {
        if (sd_bus_get_name_creds(bus_.get(), "org.caracara.Simulator1", 0, nullptr) >= 0)
            return;
        if (!sim.running())
            throw std::runtime_error("caracara-sim exited at start; see " + dir_ + "/sim.log");
        std::this_thread::sleep_for(10ms);
    }
    throw std::runtime_error("caracara-sim did not come up; see " + dir_ + "/sim.log");
}

SimFixture::~SimFixture() {
    bus_.reset();
    sim.stop();
    dbus_daemon.stop();
    if (!std::getenv("CARACARA_KEEP_TEST_DIR"))
        std::system(("rm -rf '" + dir_ + "'").c_str());
}

std::string SimFixture::write_file(const std::string& name, const std::string& text) {
    std::string p = dir_ + "/" + name;
    std::ofstream(p) << text;
    return p;
}

namespace {
[[noreturn]] void fail(const char* what, const sd_bus_error& e, int r) {
    throw std::runtime_error(std::string(what) + ": " + (e.message ? e.message : strerror(-r)));
}
} // namespace

#define GET_PROP(type, sig, cast)                                                                                 \
    sd_bus_error e = SD_BUS_ERROR_NULL;                                                                         \
    type v{};                                                                                                   \
    int r = sd_bus_get_property_trivial(bus_.get(), "org.caracara.Simulator1", thruster_path(i).c_str(),        \
                                        "org.caracara.Simulator1.Thruster", prop, &e, sig, &v);                 \
    if (r < 0)                                                                                                  \
        fail(prop, e, r);                                                                                       \
    return cast(v);

uint8_t SimFixture::thruster_byte(unsigned i, const char* prop) { GET_PROP(uint8_t, 'y', static_cast<uint8_t>) }
uint64_t SimFixture::thruster_u64(unsigned i, const char* prop) { GET_PROP(uint64_t, 't', static_cast<uint64_t>) }
double SimFixture::thruster_double(unsigned i, const char* prop) { GET_PROP(double, 'd', static_cast<double>) }
#undef GET_PROP

#define ROOT_PROP(type, sig, cast)                                                                               \
    sd_bus_error e = SD_BUS_ERROR_NULL;                                                                         \
    type v{};                                                                                                   \
    int r = sd_bus_get_property_trivial(bus_.get(), "org.caracara.Simulator1", "/org/caracara/Simulator1",      \
                                        "org.caracara.Simulator1", prop, &e, sig, &v);                          \
    if (r < 0)                                                                                                  \
        fail(prop, e, r);                                                                                       \
    return cast(v);

bool SimFixture::root_bool(const char* prop) { ROOT_PROP(int, 'b', static_cast<bool>) }
uint64_t SimFixture::root_u64(const char* prop) { ROOT_PROP(uint64_t, 't', static_cast<uint64_t>) }
uint32_t SimFixture::root_u32(const char* prop) { ROOT_PROP(uint32_t, 'u', static_cast<uint32_t>) }
#undef ROOT_PROP

std::string SimFixture::root_string(const char* prop) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    char* s = nullptr;
    int r = sd_bus_get_property_string(bus_.get(), "org.caracara.Simulator1", "/org/caracara/Simulator1",
                                       "org.caracara.Simulator1", prop, &e, &s);
    if (r < 0)
        fail(prop, e, r);
    std::string out = s;
    free(s);
    return out;
}

std::vector<uint8_t> SimFixture::thruster_bytes(unsigned i, const char* prop) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* m = nullptr;
    int r = sd_bus_get_property(bus_.get(), "org.caracara.Simulator1", thruster_path(i).c_str(),
                                "org.caracara.Simulator1.Thruster", prop, &e, &m, "ay");
    if (r < 0)
        fail(prop, e, r);
    dbus::MessagePtr guard(m);
    const void* p = nullptr;
    size_t n = 0;
    r = sd_bus_message_read_array(m, 'y', &p, &n);
    if (r < 0)
        fail(prop, e, r);
    auto* b = static_cast<const uint8_t*>(p);
    return {b, b + n};
}

std::vector<std::string> SimFixture::thruster_strings(unsigned i, const char* prop) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    char** strv = nullptr;
    int r = sd_bus_get_property_strv(bus_.get(), "org.caracara.Simulator1", thruster_path(i).c_str(),
                                     "org.caracara.Simulator1.Thruster", prop, &e, &strv);
    if (r < 0)
        fail(prop, e, r);
    std::vector<std::string> out;
    for (char** s = strv; s && *s; ++s) {
        out.emplace_back(*s);
        free(*s);
    }
    free(strv);
    return out;
}

std::string SimFixture::call(const std::string& path, const char* iface, const char* method, const char* sig, ...) {
    sd_bus_message* m = nullptr;
    int r = sd_bus_message_new_method_call(bus_.get(), &m, "org.caracara.Simulator1", path.c_str(), iface, method);
    if (r < 0)
        throw std::runtime_error("new_method_call failed");
    dbus::MessagePtr guard(m);
    va_list ap;
    va_start(ap, sig);
    r = sd_bus_message_appendv(m, sig, ap);
    va_end(ap);
    if (r < 0)
        throw std::runtime_error("append failed");
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* reply = nullptr;
    r = sd_bus_call(bus_.get(), m, 5000000, &e, &reply);
    sd_bus_message_unref(reply);
    std::string name = r < 0 ? (e.name ? e.name : "error") : "";
    sd_bus_error_free(&e);
    return name;
}

std::vector<WireEntry> SimFixture::wire_log(uint64_t since) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* reply = nullptr;
    int r = sd_bus_call_method(bus_.get(), "org.caracara.Simulator1", "/org/caracara/Simulator1",
                               "org.caracara.Simulator1", "GetWireLog", &e, &reply, "t", since);
    if (r < 0)
        fail("GetWireLog", e, r);
    return read_wire_log(reply, nullptr);
}

std::vector<WireEntry> SimFixture::wire_log_page(uint64_t since, uint32_t max_entries, uint64_t* next) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* reply = nullptr;
    int r = sd_bus_call_method(bus_.get(), "org.caracara.Simulator1", "/org/caracara/Simulator1",
                               "org.caracara.Simulator1", "GetWireLogPage", &e, &reply, "tu", since, max_entries);
    if (r < 0)
        fail("GetWireLogPage", e, r);
    return read_wire_log(reply, next);
}

// The reply of GetWireLog or GetWireLogPage (which it takes over).
std::vector<WireEntry> SimFixture::read_wire_log(sd_bus_message* reply, uint64_t* next_out) {
    dbus::MessagePtr guard(reply);
    uint64_t next = 0;
    sd_bus_message_read(reply, "t", &next);
    if (next_out)
        *next_out = next;
    std::vector<WireEntry> out;
    int r = sd_bus_message_enter_container(reply, 'a', "(tttsqbayays)");
    while (r >= 0 && sd_bus_message_enter_container(reply, 'r', "tttsqbayays") > 0) {
        WireEntry w{};
        const char* busname = nullptr;
        int read = 0;
        sd_bus_message_read(reply, "tttsqb", &w.index, &w.time_ns, &w.transaction, &busname, &w.addr, &read);
        w.bus = busname;
        w.read = read;
        const void* p = nullptr;
        size_t n = 0;
        sd_bus_message_read_array(reply, 'y', &p, &n);
        w.data.assign(static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
        sd_bus_message_read_array(reply, 'y', &p, &n);
        w.miso.assign(static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
        const char* res = nullptr;
        sd_bus_message_read(reply, "s", &res);
        w.result = res;
        sd_bus_message_exit_container(reply);
        out.push_back(std::move(w));
    }
    return out;
}

} // namespace caracara::test
