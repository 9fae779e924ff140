#include "dbus/bus_scan_reply.hpp"

#include "dbus/error_reply.hpp"

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

int fill_report(sd_bus_message* m, const BusScanReport& report) {
    int r = sd_bus_message_open_container(m, 'a', "(qiysyi)");
    for (auto d = report.devices.begin(); r >= 0 && d != report.devices.end(); ++d)
        r = append_device(m, *d);
    if (r >= 0)
        r = sd_bus_message_close_container(m);
    if (r >= 0)
        r = sd_bus_message_open_container(m, 'a', "(ss)");
    for (auto t = report.thrusters.begin(); r >= 0 && t != report.thrusters.end(); ++t)
        r = sd_bus_message_append(m, "(ss)", std::string(scan_verdict_name(t->verdict)).c_str(), t->advice.c_str());
    return r < 0 ? r : sd_bus_message_close_container(m);
}

} // namespace

int scan_bus(sd_bus_message* call, BusScan& scan) {
    scan.run(reply_filled_later(call, [&scan](sd_bus_message* out) { return fill_report(out, scan.report()); }));
    return 1;
}

} // namespace caracara::dbus
