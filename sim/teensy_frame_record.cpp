#include "sim/teensy_frame_record.hpp"

namespace caracara::sim {

std::string_view to_string(TeensyFrameOutcome o) {
    switch (o) {
    case TeensyFrameOutcome::Ok: return "ok";
    case TeensyFrameOutcome::Busy: return "busy";
    case TeensyFrameOutcome::GarbageAck: return "garbage-ack";
    case TeensyFrameOutcome::NoAnswer: return "no-answer";
    case TeensyFrameOutcome::Invalid: return "invalid";
    case TeensyFrameOutcome::Unknown: return "unknown";
    case TeensyFrameOutcome::Incomplete: return "incomplete";
    }
    return "?";
}

} // namespace caracara::sim
