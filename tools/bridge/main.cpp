// caracara-bridge: the vehicle live in Foxglove. Serves the Foxglove WebSocket protocol v1 on
// a Unix socket (default /run/caracara-bridge/bridge.sock, reached with ssh -L) or, when asked,
// on TCP with a token; a client of caracarad's D-Bus API and of nothing else (docs/foxglove.md).
#include "drivers/sdbus/program_args.hpp"
#include "tools/bridge/bridge_server.hpp"

#include <boost/asio/signal_set.hpp>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>
#include <systemd/sd-daemon.h>

namespace {

constexpr const char* kDefaultSocket = "/run/caracara-bridge/bridge.sock";
constexpr const char* kDefaultCockpit = "/usr/share/caracara/cockpit";
constexpr const char* kDefaultDives = "/var/log/caracara"; // caracarad's LogsDirectory

void help() {
    std::cout << "caracara-bridge [OPTIONS...]\n\n"
                 "Serve caracarad (org.caracara.Vehicle1) to Foxglove: the Foxglove WebSocket protocol v1\n"
                 "(foxglove.websocket.v1), channels and commands as docs/foxglove.md lists them.\n\n"
                 "  --listen unix:PATH         Listen on a Unix socket, mode 0660 (default " << kDefaultSocket << ")\n"
                 "  --listen tcp:ADDRESS:PORT  Listen on TCP instead; needs --token-file (docs/topside.md)\n"
                 "  --token-file FILE          The token every TCP client must bring (?token= or\n"
                 "                             Authorization: Bearer)\n"
                 "  --allow-origin ORIGIN      A web page's origin that may connect besides the cockpit served\n"
                 "                             here (e.g. https://app.foxglove.dev); repeatable. Pages of any\n"
                 "                             other origin are refused (403); clients that send no Origin\n"
                 "                             (Foxglove desktop, scripts) are taken (docs/foxglove.md)\n"
                 "  --max-clients N            WebSocket clients at once (default 16); a connection takes\n"
                 "                             a slot only once its request (and token) is good\n"
                 "  --cockpit-dir DIR          The cockpit's files, served to browsers on the same socket\n"
                 "                             (default " << kDefaultCockpit << "; docs/cockpit.md)\n"
                 "  --dives-dir DIR            The recorded dives the cockpit lists (default " << kDefaultDives << ")\n"
                 "  --system | --user | --bus-address ADDR   The bus caracarad is on (default: system)\n"
                 "  -h --help                  Show this help\n"
                 "  --version                  Show the version\n";
}


} // namespace

int main(int argc, char** argv) {
    caracara::bridge::ListenConfig listen{kDefaultSocket, "", 0, 16};
    caracara::bridge::SessionConfig session;
    session.cockpit_dir = kDefaultCockpit;
    session.dives_dir = kDefaultDives;
    std::string token_file;
    std::vector<std::string> allowed_origins;
    caracara::dbus::ProgramArgs args("caracara-bridge", CARACARA_VERSION, argc, argv, help);
    while (args.next(session.bus)) {
        if (args.is("--listen")) {
            const std::string l = args.value();
            if (l.starts_with("unix:") && l.size() > 5) {
                listen.unix_path = l.substr(5);
            } else if (l.starts_with("tcp:") && l.rfind(':') > 4) {
                const auto colon = l.rfind(':');
                listen.unix_path.clear();
                listen.tcp_host = l.substr(4, colon - 4);
                const std::string port = l.substr(colon + 1);
                const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), listen.tcp_port);
                if (ec != std::errc() || end != port.data() + port.size() || listen.tcp_port == 0)
                    args.usage_error("bad TCP port in '" + l + "'");
            } else {
                args.usage_error("--listen takes unix:PATH or tcp:ADDRESS:PORT, not '" + l + "'");
            }
        } else if (args.is("--cockpit-dir")) {
            session.cockpit_dir = args.value();
        } else if (args.is("--dives-dir")) {
            session.dives_dir = args.value();
        } else if (args.is("--token-file")) {
            token_file = args.value();
        } else if (args.is("--allow-origin")) {
            const std::string o = args.value();
            if (!caracara::bridge::OriginCheck::normalize(o))
                args.usage_error("--allow-origin takes an origin, scheme://host[:port] with no path (e.g. "
                                 "https://app.foxglove.dev), not '" + o + "'");
            allowed_origins.push_back(o);
        } else if (args.is("--max-clients")) {
            const std::string n = args.value();
            const auto [end, ec] = std::from_chars(n.data(), n.data() + n.size(), listen.max_clients);
            if (ec != std::errc() || end != n.data() + n.size() || listen.max_clients == 0)
                args.usage_error("--max-clients needs a positive number");
        } else {
            args.unknown();
        }
    }
    if (!listen.tcp_host.empty()) {
        // TCP reaches beyond the SSH login: never without a token.
        if (token_file.empty())
            args.usage_error("--listen tcp: needs --token-file");
        std::ifstream f(token_file);
        std::getline(f, session.token);
        if (!f && session.token.empty())
            args.usage_error("cannot read the token from " + token_file);
        if (session.token.size() < 16)
            args.usage_error("the token in " + token_file + " is shorter than 16 characters");
    } else if (!token_file.empty()) {
        args.usage_error("--token-file applies to --listen tcp: only");
    }
    session.origins = caracara::bridge::OriginCheck(allowed_origins, !session.token.empty());
    for (const std::string& o : session.origins.allowed())
        std::fprintf(stderr, "caracara-bridge: pages from %s may connect (--allow-origin)\n", o.c_str());
    try {
        boost::asio::io_context io(1);
        caracara::bridge::BridgeServer server(io, listen, session);
        boost::asio::signal_set signals(io, SIGINT, SIGTERM);
        signals.async_wait([&](boost::system::error_code, int) { io.stop(); });
        server.start();
        std::fprintf(stderr, "caracara-bridge: listening on %s\n",
                     listen.tcp_host.empty() ? ("unix:" + listen.unix_path).c_str()
                                             : ("tcp:" + listen.tcp_host + ":" + std::to_string(listen.tcp_port)).c_str());
        sd_notify(0, "READY=1");
        io.run();
        if (!listen.unix_path.empty())
            ::unlink(listen.unix_path.c_str());
    } catch (const std::exception& e) {
        std::cerr << "caracara-bridge: " << e.what() << '\n';
        return 1;
    }
    return 0;
}
