// CRC-32 (IEEE 802.3, the one of zlib and gzip: reflected 0xEDB88320, init and final xor
// 0xFFFFFFFF), so `python3 -c 'import zlib; zlib.crc32(...)'` checks a dive block by hand.
#pragma once

#include <cstdint>
#include <span>

namespace caracara {

uint32_t crc32(std::span<const uint8_t> bytes);

} // namespace caracara
