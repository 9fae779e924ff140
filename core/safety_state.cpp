#include "core/safety_state.hpp"

namespace caracara {

} // namespace caracara
