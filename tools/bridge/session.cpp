#include "tools/bridge/session.hpp"

#include "tools/bridge/dive_routes.hpp"
#include "tools/bridge/dive_worker.hpp"
#include "tools/bridge/static_files.hpp"

#include "tools/client/same_secret.hpp"
#include "tools/foxglove/channels.hpp"

#include <boost/algorithm/string/predicate.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/http/read.hpp>
#include <boost/beast/http/write.hpp>
#include <boost/beast/websocket/rfc6455.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace caracara::bridge {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace fg = caracara::foxglove;

namespace {

constexpr const char* kSubprotocol = "foxglove.websocket.v1";
constexpr uint8_t kMessageData = 0x01;
// From the connection to its request read (a stalled or silent connection goes then), and
// from the request to an HTTP answer written (a reader that never reads goes then; a dive of
// up to 32 MiB gets longer, for a slow tether).
constexpr auto kRequestTimeout = std::chrono::seconds(3);
constexpr auto kAnswerTimeout = std::chrono::seconds(60);
constexpr auto kDiveAnswerTimeout = std::chrono::minutes(5);
// A client being closed for what it did: its close frame gets this long to go out.
constexpr auto kCloseTimeout = std::chrono::seconds(2);

// The HTTP request's token: "Authorization: Bearer T" (the scheme in any case, RFC 7235 2.1)
// or "?token=T" (a browser's WebSocket cannot set headers, so Foxglove's URL carries it).
std::string_view view(beast::string_view s) { return {s.data(), s.size()}; }

std::string token_of(const http::request<http::string_body>& req) {
    constexpr std::string_view kScheme = "bearer ";
    const std::string_view auth = view(req[http::field::authorization]);
    if (auth.size() > kScheme.size() && boost::algorithm::iequals(auth.substr(0, kScheme.size()), kScheme))
        return std::string(auth.substr(kScheme.size()));
    const std::string_view target = view(req.target());
    const auto q = target.find("token=");
    if (q == std::string_view::npos || (q > 0 && target[q - 1] != '?' && target[q - 1] != '&'))
        return "";
    const auto end = target.find('&', q);
    return std::string(target.substr(q + 6, end == std::string_view::npos ? std::string_view::npos : end - q - 6));
}

bool offers_subprotocol(const http::request<http::string_body>& req) {
    const std::string_view offered = view(req[http::field::sec_websocket_protocol]);
    std::size_t at = 0;
    while (at <= offered.size()) {
        const auto comma = offered.find(',', at);
        std::string_view item = offered.substr(at, comma == std::string_view::npos ? std::string_view::npos : comma - at);
        while (!item.empty() && item.front() == ' ')
            item.remove_prefix(1);
        while (!item.empty() && item.back() == ' ')
            item.remove_suffix(1);
        if (item == kSubprotocol)
            return true;
        if (comma == std::string_view::npos)
            break;
        at = comma + 1;
    }
    return false;
}

std::string server_info() {
    return nlohmann::json{{"op", "serverInfo"},
                          {"name", "caracara-bridge"},
                          {"capabilities", {"clientPublish"}},
                          {"supportedEncodings", {"json"}},
                          {"metadata", nlohmann::json::object()}}
        .dump();
}

std::string advertise() {
    nlohmann::json list = nlohmann::json::array();
    const auto& all = fg::channels();
    for (std::size_t i = 0; i < all.size(); ++i)
        list.push_back({{"id", i + 1},
                        {"topic", all[i].topic},
                        {"encoding", fg::kEncoding},
                        {"schemaName", all[i].schema_name},
                        {"schema", all[i].schema},
                        {"schemaEncoding", fg::kSchemaEncoding}});
    return nlohmann::json{{"op", "advertise"}, {"channels", list}}.dump();
}

} // namespace

Session::Session(boost::asio::io_context& io, Socket socket, const SessionConfig& config, Telemetry& telemetry,
                 ClientSlots& slots, DiveWorker& dives)
    : io_(io), ws_(std::move(socket)), timer_(io), config_(config), telemetry_(telemetry), slots_(slots),
      dives_(dives), protocol_(fg::channels().size()), queue_(config.max_queued, config.max_reply_bytes) {}

void Session::start() {
    close_after(kRequestTimeout);
    http::async_read(ws_.next_layer(), buffer_, request_,
                     [self = shared_from_this()](boost::system::error_code ec, std::size_t) { self->on_request(ec); });
}

void Session::close_after(std::chrono::steady_clock::duration d) {
    timer_.expires_after(d);
    timer_.async_wait([weak = weak_from_this()](boost::system::error_code ec) {
        if (auto self = weak.lock(); self && !ec)
            self->close_socket();
    });
}

void Session::close_socket() {
    boost::system::error_code ignored;
    ws_.next_layer().shutdown(Socket::shutdown_both, ignored);
    ws_.next_layer().close(ignored);
}

void Session::drop() {
    timer_.cancel();
    close_socket();
}

void Session::reject(http::status status, std::string body) {
    auto res = std::make_shared<http::response<http::string_body>>(status, request_.version());
    res->set(http::field::content_type, "text/plain");
    res->body() = std::move(body) + "\n";
    res->keep_alive(false);
    res->prepare_payload();
    answer(std::move(res));
}

bool Session::origin_taken(bool upgrade) {
    const auto field = request_.find(http::field::origin);
    const std::optional<std::string_view> origin =
        field == request_.end() ? std::nullopt : std::optional<std::string_view>(view(field->value()));
    const auto verdict = config_.origins.judge(origin, view(request_[http::field::host]));
    if (!config_.origins.refused(verdict))
        return true;
    // The origin is the page's, the host the browser's: both are only printed, never trusted.
    auto printable = [](std::string_view s) {
        std::string out(s.substr(0, 200));
        for (char& c : out)
            c = (c < 0x20 || c > 0x7e) ? '?' : c;
        return out;
    };
    const std::string from = printable(*origin), host = printable(view(request_[http::field::host]));
    const bool rebind = verdict == OriginCheck::Verdict::Rebindable;
    const std::string why = rebind ? "the bridge's Host '" + host + "' is a name that DNS rebinding can forge (use "
                                     "localhost or an IP address, or give --allow-origin " + from + ")"
                                   : "not the bridge's own page (http://" + host + ") nor given with --allow-origin";
    std::fprintf(stderr, "caracara-bridge: refused %s from origin '%s': %s\n",
                 upgrade ? "a WebSocket upgrade" : "a request for dives", from.c_str(), why.c_str());
    reject(http::status::forbidden, "caracara-bridge: a page from " + from + " may not use this bridge: " + why +
                                        " (docs/foxglove.md, \"Which pages may connect\")");
    return false;
}

void Session::answer(std::shared_ptr<http::response<http::string_body>> res, std::shared_ptr<void> ticket) {
    close_after(ticket ? kDiveAnswerTimeout : kAnswerTimeout);
    http::async_write(ws_.next_layer(), *res, [self = shared_from_this(), res, ticket](boost::system::error_code, std::size_t) {
        boost::system::error_code ignored;
        self->ws_.next_layer().shutdown(Socket::shutdown_both, ignored);
    });
}

void Session::on_request(boost::system::error_code ec) {
    got_request_ = true;
    timer_.cancel();
    if (ec)
        return close_socket(); // not HTTP, or gone before the request
    // A plain GET of the cockpit's files: the same for everyone, so without the token (the page
    // passes its own URL's token to its WebSocket and to /dives/; no vehicle data comes without it).
    const bool upgrade = websocket::is_upgrade(request_);
    const bool dives = view(request_.target()).starts_with(DiveRoutes::kPrefix);
    if (!upgrade && !dives)
        return answer(std::make_shared<http::response<http::string_body>>(
            StaticFiles(config_.cockpit_dir).respond(request_)));
    if (!origin_taken(upgrade))
        return;
    if (!config_.token.empty() && !client::same_secret(token_of(request_), config_.token))
        return reject(http::status::unauthorized, "caracara-bridge: a valid token is required");
    if (!upgrade) {
        // Listing and converting take their time: on the worker, never on this (the I/O) thread.
        close_after(kDiveAnswerTimeout);
        const bool queued = dives_.submit(std::make_shared<const http::request<http::string_body>>(request_),
                                          [self = shared_from_this()](StaticFiles::Response res, std::shared_ptr<void> ticket) {
                                              self->answer(std::make_shared<http::response<http::string_body>>(std::move(res)),
                                                           std::move(ticket));
                                          });
        if (!queued)
            reject(http::status::service_unavailable, "caracara-bridge: too many dive requests in progress; try again");
        return;
    }
    if (!offers_subprotocol(request_))
        return reject(http::status::bad_request, std::string("caracara-bridge needs the subprotocol ") + kSubprotocol);
    slot_ = slots_.claim();
    if (!slot_)
        return reject(http::status::service_unavailable,
                      "caracara-bridge: " + std::to_string(slots_.max()) + " clients are connected already");
    try {
        link_ = std::make_unique<CommandLink>(
            io_, config_.bus,
            [this](std::string_view topic, const std::string& name, const std::string& message) {
                send_text(status_json(2, std::string(topic) + " refused: " + name + (message.empty() ? "" : ": " + message)));
            },
            [this](std::string_view topic, const std::string& json) { send_text(status_json(0, json, topic)); },
            // Not from inside the link's own processing: the session ends on the next turn.
            [this] { boost::asio::post(io_, [self = shared_from_this()] { self->end("the bus connection closed"); }); });
    } catch (const std::exception& e) {
        return reject(http::status::service_unavailable, std::string("caracara-bridge: ") + e.what());
    }
    ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
        res.set(http::field::sec_websocket_protocol, kSubprotocol);
        res.set(http::field::server, "caracara-bridge");
    }));
    websocket::stream_base::timeout timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
    timeouts.handshake_timeout = kRequestTimeout;
    timeouts.idle_timeout = std::chrono::seconds(10);
    timeouts.keep_alive_pings = true;
    ws_.set_option(timeouts);
    ws_.read_message_max(config_.max_message_bytes);
    ws_.async_accept(request_, [self = shared_from_this()](boost::system::error_code e) { self->on_accept(e); });
}

void Session::on_accept(boost::system::error_code ec) {
    if (ec)
        return end("handshake failed");
    open_ = true;
    send_text(server_info());
    send_text(advertise());
    read();
}

void Session::read() {
    buffer_.clear();
    ws_.async_read(buffer_, [self = shared_from_this()](boost::system::error_code ec, std::size_t) { self->on_frame(ec); });
}

void Session::on_frame(boost::system::error_code ec) {
    if (ec == websocket::error::message_too_big) {
        // Beast closes with "message too big" (1009); the client hears why.
        return end("message too big");
    }
    if (ec)
        return end(nullptr);
    const auto data = buffer_.cdata();
    const auto* bytes = static_cast<const uint8_t*>(data.data());
    if (ws_.got_text())
        handle(protocol_.on_text({reinterpret_cast<const char*>(bytes), data.size()}));
    else
        handle(protocol_.on_binary({bytes, data.size()}));
    if (ended_)
        return;
    // A client that sends and does not read its replies is read no further until it has.
    if (queue_.reply_bytes() > config_.read_pause_bytes)
        paused_ = true;
    else
        read();
}

void Session::handle(const Outcome& outcome) {
    for (const std::string& reply : outcome.replies)
        send_text(reply);
    if (outcome.command && link_)
        link_->send(*outcome.command);
    for (const uint32_t channel : outcome.subscribed)
        if (const Payload latest = telemetry_.latest(channel - 1))
            deliver(channel - 1, 0, latest);
}

void Session::deliver(std::size_t channel, uint64_t time_ns, const Payload& json) {
    if (!open_ || ended_)
        return;
    if (time_ns == 0) {
        timespec t{};
        clock_gettime(CLOCK_REALTIME, &t);
        time_ns = static_cast<uint64_t>(t.tv_sec) * 1'000'000'000u + static_cast<uint64_t>(t.tv_nsec);
    }
    for (const uint32_t sub : protocol_.subscribers(static_cast<uint32_t>(channel + 1))) {
        auto frame = std::make_shared<std::string>(13 + json->size(), '\0');
        (*frame)[0] = static_cast<char>(kMessageData);
        for (int i = 0; i < 4; ++i)
            (*frame)[1 + static_cast<std::size_t>(i)] = static_cast<char>(sub >> (8 * i));
        for (int i = 0; i < 8; ++i)
            (*frame)[5 + static_cast<std::size_t>(i)] = static_cast<char>(time_ns >> (8 * i));
        frame->replace(13, json->size(), *json);
        queue({false, true, std::move(frame)});
    }
}

void Session::send_text(std::string text) {
    if (open_ && !ended_)
        queue({true, false, std::make_shared<const std::string>(std::move(text))});
}

void Session::queue(Frame f) {
    if (!queue_.push(std::move(f)))
        return end("its replies passed their bound (it sends and does not read)", true);
    if (!queue_.writing())
        write_next();
}

void Session::write_next() {
    if (queue_.empty() || ended_)
        return;
    const Frame& f = queue_.start_front();
    ws_.text(f.text);
    ws_.async_write(boost::asio::buffer(*f.bytes), [self = shared_from_this()](boost::system::error_code ec, std::size_t) {
        self->queue_.pop_front();
        if (ec)
            return self->end("a write failed");
        if (self->paused_ && !self->ended_ && self->queue_.reply_bytes() <= self->config_.read_pause_bytes) {
            self->paused_ = false;
            self->read();
        }
        self->write_next();
    });
}

void Session::end(const char* why, bool tell_client) {
    if (ended_)
        return;
    ended_ = true;
    // The pilot's D-Bus connection goes now: caracarad zeroes what this client commanded.
    link_.reset();
    if (why)
        std::fprintf(stderr, "caracara-bridge: closing a client: %s\n", why);
    if (!tell_client || !open_) {
        timer_.cancel();
        return close_socket();
    }
    // The close frame with the reason goes after the frame in flight, if the client reads it;
    // if it does not, the socket is closed soon after anyway.
    queue_.clear_waiting();
    close_after(kCloseTimeout);
    ws_.async_close(websocket::close_reason(websocket::close_code::policy_error, why),
                    [self = shared_from_this()](boost::system::error_code) { self->close_socket(); });
}

} // namespace caracara::bridge
