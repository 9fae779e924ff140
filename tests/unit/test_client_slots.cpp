// caracara-bridge's client slots (tools/bridge/client_slots.hpp): at most max held at once, a
// slot freed when the last copy of its handle goes, even after the ClientSlots itself.
#include "tests/catch.hpp"
#include "tools/bridge/client_slots.hpp"

#include <vector>

using caracara::bridge::ClientSlots;

TEST_CASE("no more slots than the bound; a released one is taken again", "[bridge]") {
    ClientSlots slots(2);
    std::vector<std::shared_ptr<void>> held{slots.claim(), slots.claim()};
    CHECK(held[0]);
    CHECK(held[1]);
    CHECK(slots.taken() == 2);
    CHECK_FALSE(slots.claim()); // full: empty, and nothing counted
    CHECK(slots.taken() == 2);
    auto copy = held[0];
    held[0].reset();
    CHECK(slots.taken() == 2); // a copy still holds it
    copy.reset();
    CHECK(slots.taken() == 1);
    CHECK(slots.claim());      // taken and at once released (the handle is not kept)
    CHECK(slots.taken() == 1);
}

TEST_CASE("a handle that outlives its ClientSlots is released safely", "[bridge]") {
    std::shared_ptr<void> handle;
    {
        ClientSlots slots(1);
        handle = slots.claim();
        CHECK(handle);
    }
    handle.reset(); // the counter is shared: no use after free (ASan runs check it)
    SUCCEED();
}
