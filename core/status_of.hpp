// The one mapping from each core error to the Status a caller gets (and so to its error name in
// core/status.cpp): a refused packet, budget, mix or safety request reads the same wherever
// it is refused.
#pragma once

#include "core/budget.hpp"
#include "core/mixing.hpp"
#include "core/packet.hpp"
#include "core/safety.hpp"
#include "core/status.hpp"

namespace caracara {

Status status_of(PacketError e);
Status status_of(BudgetError e);
Status status_of(MixError e);
Status status_of(SafetyError e);

} // namespace caracara
