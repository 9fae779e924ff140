// Where zero orders go on their way to the thrusters: in front of everything queued, which is
// dropped (a kill), or behind it (a command timeout or a client that left: what it had sent
// goes out first). Decided by the vehicle, carried out by the bus: both see it here.
#pragma once

namespace caracara {

enum class ZeroOrder { First, Behind };

} // namespace caracara
