#include "dbus/error_reply.hpp"

#include "dbus/vehicle_names.hpp"

#include <memory>

namespace caracara::dbus {

std::string error_name(Status s) { return std::string(kErrorPrefix) + std::string(status_name(s)); }

int reply(sd_bus_message* call, const Result& result) {
    if (result.ok())
        return sd_bus_reply_method_return(call, "");
    const std::string name = error_name(result.status);
    sd_bus_error error = SD_BUS_ERROR_NULL;
    sd_bus_error_set(&error, name.c_str(), result.message.c_str());
    const int r = sd_bus_reply_method_error(call, &error);
    sd_bus_error_free(&error);
    return r;
}

Completion reply_later(sd_bus_message* call) {
    auto held = std::shared_ptr<sd_bus_message>(sd_bus_message_ref(call), sd_bus_message_unref);
    return [held](const Result& result) { reply(held.get(), result); };
}

Completion reply_filled_later(sd_bus_message* call, std::function<int(sd_bus_message* out)> fill) {
    auto held = std::shared_ptr<sd_bus_message>(sd_bus_message_ref(call), sd_bus_message_unref);
    return [held, fill = std::move(fill)](const Result& result) {
        if (!result.ok()) {
            reply(held.get(), result);
            return;
        }
        sd_bus_message* m = nullptr;
        int r = sd_bus_message_new_method_return(held.get(), &m);
        MessagePtr out(r < 0 ? nullptr : m);
        if (r >= 0)
            r = fill(out.get());
        if (r < 0 || sd_bus_send(nullptr, out.get(), nullptr) < 0)
            reply(held.get(), Result{Status::Hardware, "cannot build the reply"});
    };
}

} // namespace caracara::dbus
