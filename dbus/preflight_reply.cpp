#include "dbus/preflight_reply.hpp"

#include "dbus/error_reply.hpp"
#include "drivers/sdbus/sdbus.hpp"

#include <memory>

namespace caracara::dbus {

namespace {

int reply_rows(sd_bus_message* call, const Preflight& p) {
    MessagePtr out;
    sd_bus_message* m = nullptr;
    int r = sd_bus_message_new_method_return(call, &m);
    if (r < 0)
        return r;
    out.reset(m);
    if ((r = sd_bus_message_open_container(m, 'a', "(sbss)")) < 0)
        return r;
    for (const PreflightRow& row : p.rows())
        if ((r = sd_bus_message_append(m, "(sbss)", row.name().c_str(), int(row.go), row.observed.c_str(),
                                       row.advice.c_str())) < 0)
            return r;
    if ((r = sd_bus_message_close_container(m)) < 0)
        return r;
    return sd_bus_send(nullptr, m, nullptr);
}

} // namespace

int run_preflight(sd_bus_message* call, Preflight& preflight) {
    auto held = std::shared_ptr<sd_bus_message>(sd_bus_message_ref(call), sd_bus_message_unref);
    preflight.run([held, &preflight](const Result& r) {
        if (!r.ok() || reply_rows(held.get(), preflight) < 0)
            reply(held.get(), r.ok() ? Result{Status::Hardware, "cannot build the reply"} : r);
    });
    return 1;
}

} // namespace caracara::dbus
