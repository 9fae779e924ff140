// Where a configured GPIO chip is, for libgpiod 2, which opens chips by path only. libgpiod
// 1.6's lookup (gpiod_chip_open_lookup) took a number ("0"), else a label ("pinctrl-rp1"), else
// a name under /dev ("gpiochip0") or a path starting with /dev/, in that order; configurations
// written for Debian 12 use all four, so the v2 backend looks chips up the same way.
#pragma once

#include <string>

namespace caracara {

// The device path for `descr`; for a label no chip has, "/dev/" + descr (opening it then fails
// with ENOENT, as v1's lookup did).
std::string libgpiod2_chip_path(const std::string& descr);

} // namespace caracara
