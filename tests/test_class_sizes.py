"""tests/class_sizes.py's counter of public methods, on small headers written here (CTest
class_sizes_test): what it counts, and what it leaves out."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import class_sizes  # noqa: E402

HOUSE = r'''
// A class as the house writes one: comments with { braces ( and "quotes", inline bodies,
// an initialiser list, nested types, overloads.
#pragma once
#define LOOKS_LIKE(x) void x();
namespace caracara {

class Widget final : public Base, public Other::Listener {
public:
    static constexpr uint64_t kNone = std::numeric_limits<uint64_t>::max();
    struct Listener {
        virtual ~Listener() = default;
        virtual void heard(int a) = 0;
    };
    enum class Mode : uint8_t { Off, On };
    using Fn = std::function<void(const Job&)>;

    explicit Widget(Config& c) : config_(c), table_{1, 2} { start("{"); }
    ~Widget() override;
    Widget(const Widget&) = delete;
    Widget& operator=(const Widget&) = delete;
    bool operator==(const Widget&) const = default;

    // Overloads of one name count once.
    Result kill(KillSource source, std::string_view reason = {});
    void kill(KillSource source, std::string_view reason, Completion done) {
        after(std::move(done), kill(source, reason));
    }
    const Monitor& monitor() const { return monitor_; }
    Monitor& monitor() { return monitor_; }
    std::string start(sd_event* event, std::function<void(const Job&)> done);
    void stop() override { worker_.stop(); }
    template <typename T> T value(std::size_t i) const { return T(values_[i]); }
    [[nodiscard]] bool idle() const noexcept { return n_ == 0; }
    auto size() const -> std::size_t { return values_.size(); }
    void heard(int a) override;
    std::function<void()> callback_ = [] { };
    int plain_ = 3;
    friend class Friend;

protected:
    void hidden();

private:
    void secret() { if (x_) { y_ = '}'; } }
    Config& config_;
    std::array<int, 2> table_{};
    std::vector<std::function<void()>> when_idle_;
    Monitor monitor_{config_, Mode::Off};
    int n_ = 0;
};

struct Plain {
    int a = 0;
    bool ok() const { return a > 0; }
private:
    void not_public();
};

enum class Colour { Red, Green };

} // namespace caracara
'''


class CounterTest(unittest.TestCase):
    def setUp(self):
        self.found = class_sizes.public_methods(HOUSE)

    def test_public_methods_counted(self):
        self.assertEqual(self.found["Widget"],
                         {"kill", "monitor", "start", "stop", "value", "idle", "size", "heard"})

    def test_struct_defaults_to_public(self):
        self.assertEqual(self.found["Plain"], {"ok"})

    def test_nested_class_counted_on_its_own(self):
        self.assertEqual(self.found["Listener"], {"heard"})

    def test_enums_are_not_classes(self):
        self.assertNotIn("Colour", self.found)
        self.assertNotIn("Mode", self.found)

    def test_over_the_limit_is_seen(self):
        many = "class Big {\npublic:\n%s};\n" % "".join(
            "    void m%d();\n" % i for i in range(class_sizes.METHOD_LIMIT + 1))
        self.assertEqual(len(class_sizes.public_methods(many)["Big"]), class_sizes.METHOD_LIMIT + 1)


if __name__ == "__main__":
    unittest.main()
