#include "core/status.hpp"

namespace caracara {

} // namespace caracara
