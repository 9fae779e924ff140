#include "core/failsafe_config.hpp"

#include <cmath>
#include <string>

namespace caracara {

namespace {

void parse_rule(Checker& c, const toml::table& t, FailsafeCondition cond, FailsafeRule& out) {
    const std::string p = "failsafe." + std::string(condition_name(cond)) + ".";
    const bool fixed = condition_is_fixed(cond);
    // A fixed condition's timing is the daemon's own (three failed transfers, the bus recovery,
    // a link that went): only its action can be written, and only as "kill". Pilot-lost's
    // persistence can be written too, within a minute: its kill must still come.
    const bool timed = condition_has_persistence(cond);
    if (timed)
        c.only_keys(t, p, {"action", "persistence_ms"});
    else
        c.only_keys(t, p, {"action"});
    std::string name;
    if (c.string(t, p, "action", name)) {
        const auto a = action_from_name(name);
        if (!a)
            c.fail(p + "action", "must be \"warn\", \"exclude\", \"surface\" or \"kill\", got \"" + name + "\"",
                   t.get("action"));
        else if (fixed && *a != FailsafeAction::Kill)
            c.fail(p + "action",
                   std::string(kFixedFailsafeError) + ": " + std::string(condition_name(cond)) +
                       " is fixed at \"kill\" (it protects people); \"" + name + "\" would weaken it",
                   t.get("action"));
        else
            out.action = *a;
    }
    if (timed)
        c.integer(t, p, "persistence_ms", 0, fixed ? kPilotLostPersistenceMaxMs : 600000, out.persistence_ms);
}

void parse_surface(Checker& c, const toml::table& t, SurfaceSettings& out) {
    const std::string p = "failsafe.surface.";
    c.only_keys(t, p, {"heave", "duration_ms"});
    if (const toml::node* n = t.get("heave")) {
        double v = 0;
        if (const auto* iv = n->as_integer())
            v = static_cast<double>(iv->get());
        else if (const auto* fv = n->as_floating_point())
            v = fv->get();
        else
            v = NAN;
        // Up is negative z; a zero or downward "ascent" would keep the vehicle where it is.
        if (!std::isfinite(v) || v < -1.0 || v >= 0.0)
            c.fail(p + "heave", "must be a z axis demand in -1..0 (negative is up), got " + written(*n), n);
        else
            out.heave = v;
    }
    c.integer(t, p, "duration_ms", 1, 600000, out.duration_ms);
}

} // namespace

void parse_failsafe(Checker& c, const toml::table& t, FailsafeSettings& out) {
    for (auto&& [k, v] : t) {
        const std::string key = "failsafe." + std::string(k.str());
        if (k.str() == "surface") {
            if (const toml::table* s = c.table(t, "failsafe.", "surface"))
                parse_surface(c, *s, out.surface);
            continue;
        }
        const auto cond = condition_from_name(k.str());
        if (!cond) {
            std::string known = "surface";
            for (std::size_t i = 0; i < kFailsafeConditionCount; ++i)
                known += ", " + std::string(condition_name(static_cast<FailsafeCondition>(i)));
            c.fail(key, "is not a failsafe condition; known: " + known, &v);
            continue;
        }
        if (const toml::table* r = c.table(t, "failsafe.", k.str()))
            parse_rule(c, *r, *cond, out.rule(*cond));
    }
}

} // namespace caracara
