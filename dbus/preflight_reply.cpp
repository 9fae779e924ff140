#include "dbus/preflight_reply.hpp"

#include "dbus/error_reply.hpp"

namespace caracara::dbus {

int run_preflight(sd_bus_message* call, Preflight& preflight) {
    preflight.run(reply_filled_later(call, [&preflight](sd_bus_message* out) {
        int r = sd_bus_message_open_container(out, 'a', "(sbss)");
        for (auto row = preflight.rows().begin(); r >= 0 && row != preflight.rows().end(); ++row)
            r = sd_bus_message_append(out, "(sbss)", row->name().c_str(), int(row->go), row->observed.c_str(),
                                      row->advice.c_str());
        return r < 0 ? r : sd_bus_message_close_container(out);
    }));
    return 1;
}

} // namespace caracara::dbus
