#include "dbus/bus_scan_reply.hpp"

#include "dbus/error_reply.hpp"

#include <memory>
#include <string>

namespace caracara::dbus {

namespace {

// (mux address, 0 on the trunk; channel, -1 on the trunk; MT; variant, "" for no thruster;
// software revision; configured thruster, -1 unexpected)
int append_device(sd_bus_message* m, const ScanDevice& d) {
    const std::string variant = d.variant ? std::string(variant_name(*d.variant)) : std::string();
    return sd_bus_message_append(m, "(qiysyi)", uint16_t(d.segment ? d.segment->addr7 : 0),
                                 int32_t(d.segment ? d.segment->channel : -1), d.mt, variant.c_str(), d.revision,
                                 d.thruster);
}

int send_report(sd_bus_message* call, const BusScanReport& report) {
    sd_bus_message* raw = nullptr;
    if (int r = sd_bus_message_new_method_return(call, &raw); r < 0)
        return r;
    const MessagePtr m(raw);
    int r = sd_bus_message_open_container(m.get(), 'a', "(qiysyi)");
    for (auto d = report.devices.begin(); r >= 0 && d != report.devices.end(); ++d)
        r = append_device(m.get(), *d);
    if (r >= 0)
        r = sd_bus_message_close_container(m.get());
    if (r >= 0)
        r = sd_bus_message_open_container(m.get(), 'a', "(ss)");
    for (auto t = report.thrusters.begin(); r >= 0 && t != report.thrusters.end(); ++t)
        r = sd_bus_message_append(m.get(), "(ss)", std::string(scan_verdict_name(t->verdict)).c_str(),
                                  t->advice.c_str());
    if (r >= 0)
        r = sd_bus_message_close_container(m.get());
    return r < 0 ? r : sd_bus_send(nullptr, m.get(), nullptr);
}

} // namespace

int scan_bus(sd_bus_message* call, BusScan& scan) {
    auto held = std::shared_ptr<sd_bus_message>(sd_bus_message_ref(call), sd_bus_message_unref);
    scan.run([held, &scan](const Result& r) {
        if (!r.ok())
            reply(held.get(), r);
        else if (send_report(held.get(), scan.report()) < 0)
            reply(held.get(), {Status::Hardware, "cannot build the ScanBus reply"});
    });
    return 1;
}

} // namespace caracara::dbus
