// Another holder of the I2C adapter's device node (the emergency stop's own connection) that
// must let go of it while the adapter's driver is unbound, and may take it again once it is
// back: the kernel's i2c_del_adapter() waits until every open /dev/i2c-N is closed, so the
// unbinding write would never return.
#pragma once

#include <string>

namespace caracara {

class I2cNodeHolder {
public:
    virtual ~I2cNodeHolder() = default;
    virtual void release() = 0;
    // Opens the node again; "" or why not (then it stays released).
    virtual std::string reopen() = 0;
};

} // namespace caracara
