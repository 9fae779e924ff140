#include "sim/pca9544.hpp"

namespace caracara::sim {

void Pca9544::on_write(std::span<const uint8_t> data, uint64_t) {
    if (!data.empty())
        control_ = static_cast<uint8_t>(data.back() & 0x07);
}

void Pca9544::on_read(std::span<uint8_t> out, uint64_t) {
    for (auto& b : out)
        b = control_;
}

std::optional<uint8_t> Pca9544::selected() const {
    if (!(control_ & 0x04))
        return std::nullopt;
    return static_cast<uint8_t>(control_ & 0x03);
}

} // namespace caracara::sim
