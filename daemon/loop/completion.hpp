// A call's result, handed back when the daemon decides the call is over (a Kill once its zeros
// are on the wire, a Turn once the Teensy confirms it): the D-Bus object replies from it.
#pragma once

#include "core/status.hpp"

#include <functional>

namespace caracara {

using Completion = std::function<void(const Result&)>;

} // namespace caracara
