#include "dbus/preflight_reply.hpp"

#include "dbus/error_reply.hpp"

#include <memory>

namespace caracara::dbus {

namespace {

int reply_rows(sd_bus_message* call, const Preflight& p) {
    MessagePtr out;
    int r = new_method_return(call, out);
    if (r >= 0)
        r = sd_bus_message_open_container(out.get(), 'a', "(sbss)");
    for (auto row = p.rows().begin(); r >= 0 && row != p.rows().end(); ++row)
        r = sd_bus_message_append(out.get(), "(sbss)", row->name().c_str(), int(row->go), row->observed.c_str(),
                                  row->advice.c_str());
    if (r >= 0)
        r = sd_bus_message_close_container(out.get());
    return r < 0 ? r : sd_bus_send(nullptr, out.get(), nullptr);
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
