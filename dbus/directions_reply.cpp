#include "dbus/directions_reply.hpp"

#include "dbus/error_reply.hpp"

namespace caracara::dbus {

int run_detection(sd_bus_message* call, DirectionDetection& d, const std::string& caller) {
    d.run(caller, reply_filled_later(call, [&d](sd_bus_message* out) {
        int r = sd_bus_message_open_container(out, 'a', "(sddddd)");
        for (auto f = d.findings().begin(); r >= 0 && f != d.findings().end(); ++f) {
            const std::string verdict(verdict_name(f->judgement.verdict));
            r = sd_bus_message_append(out, "(sddddd)", verdict.c_str(), f->change[0], f->change[1], f->change[2],
                                      f->judgement.along, f->judgement.margin);
        }
        if (r >= 0)
            r = sd_bus_message_close_container(out);
        return r < 0 ? r : sd_bus_message_append(out, "s", d.fragment().c_str());
    }));
    return 1;
}

} // namespace caracara::dbus
