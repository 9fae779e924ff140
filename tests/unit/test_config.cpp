#include "core/config.hpp"

#include "tests/catch.hpp"
#include <cctype>
#include <fstream>
#include <random>
#include <vector>
#include <map>
#include <sstream>

using namespace caracara;

namespace {

const char* const kDefaultMt[] = {"0x52", "0x56", "0x58", "0x5A", "0x5C", "0x5E", "0x60", "0x62"};

// Eight [[thruster]] sections with the default addresses; `body` replaces a section's
// contents (an "address" line is added unless the body has one).
std::string thrusters(const std::map<int, std::string>& body = {}, int count = 8) {
    std::string out;
    for (int i = 0; i < count; ++i) {
        out += "[[thruster]]\n";
        const auto it = body.find(i);
        const std::string b = it == body.end() ? "" : it->second;
        const bool has_address = b.rfind("address =", 0) == 0 || b.find("\naddress =") != std::string::npos;
        if (!has_address)
            out += std::string("address = ") + kDefaultMt[i % 8] + "\n";
        out += b + "\n";
    }
    return out;
}

std::string errors_of(const std::string& text) {
    const ConfigResult r = parse_config_string(text);
    CHECK_FALSE(r.ok());
    return r.error();
}

void check_error(const std::string& text, const std::string& expected) {
    INFO("config:\n" << text);
    const std::string err = errors_of(text);
    CHECK_THAT(err, Catch::Contains(expected));
}

} // namespace

TEST_CASE("an empty file gives the documented defaults") {
    const ConfigResult r = parse_config_string("");
    REQUIRE(r.ok());
    CHECK(r.error().empty());
    const DaemonConfig& c = *r.config;
    CHECK(c.i2c.device == "/dev/i2c-1");
    CHECK(c.i2c.clock_hz == 100000);
    CHECK(c.i2c.timeout_ms == 20u); // a hung thruster holds a transfer 20 ms, not the kernel's 1 s
    CHECK_FALSE(c.i2c.retries);
    CHECK(c.spi.device == "/dev/spidev0.0");
    CHECK(c.spi.spi.speed_hz == 500000);
    CHECK(c.spi.spi.byte_delay_us == 0);
    CHECK(c.spi.fitted);              // the vehicle has a Teensy: absent at start is a kill
    CHECK(c.spi.silence_ms == 200u);  // ten polls at 50 Hz
    const std::array<uint8_t, 8> mts{0x52, 0x56, 0x58, 0x5A, 0x5C, 0x5E, 0x60, 0x62};
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        INFO("thruster " << i);
        CHECK(c.thrusters[i].mt == mts[i]);
        CHECK(c.thrusters[i].variant == Variant::SeaBotix);
        CHECK(c.thrusters[i].info == 100);
        CHECK_FALSE(c.thrusters[i].mux);
        CHECK_FALSE(c.thrusters[i].reversed);
    }
    CHECK(validate_thruster_set(c.thrusters).empty());
    CHECK(c.mixing == default_mix_matrix());
    CHECK(c.control.loop_rate_hz == 50);
    CHECK(c.control.status_reads_per_tick == 1);
    CHECK(c.control.command_timeout_ms == 500);
    CHECK(c.control.arming_delay_ms == 3000);
    CHECK(c.control.budget_policy == BudgetPolicy::Scale);
    CHECK_FALSE(c.gpio.kill_switch);
    CHECK_FALSE(c.gpio.kill_output);
    CHECK_FALSE(c.gpio.power_off_output);
    CHECK_FALSE(c.gpio.scl);
    CHECK_FALSE(c.gpio.sda);
    CHECK_FALSE(c.recovery.enabled);
    CHECK(c.recovery.attempts == 3);
    CHECK(c.recovery.driver_id.empty());

    const SafetyConfig s = safety_config(c);
    CHECK(s.arming_delay_ns == 3'000'000'000ull);
    CHECK(s.command_timeout_ns == 500'000'000ull);
}

TEST_CASE("a full file is parsed into the structs") {
    const std::string text = R"(
[i2c]
device = "/dev/i2c-3"
timeout_ms = 200
retries = 2
[spi]
device = "/dev/spidev1.0"
speed_hz = 1000000
per_byte_delay_us = 20
busy_retries = 5
busy_delay_us = 500
servos = 2
distance_sensors = 6
[control]
loop_rate_hz = 0
status_reads_per_tick = 8
command_timeout_ms = 250
arming_delay_ms = 0
budget_policy = "reject"
[gpio]
kill_switch = { chip = "gpiochip1", line = 17, active_low = true }
kill_output = { line = "KILL" }
scl = { line = "GPIO3" }
sda = { line = "GPIO2" }
[recovery]
enabled = true
attempts = 5
backoff_ms = 50
driver_id = "fe804000.i2c"
device_wait_ms = 2000
[mixing]
matrix = [[0.5, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0],
          [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, -1.0]]
)" + thrusters({{0, "address = 0x54\nvariant = \"legacy\"\ninfo = 7\nreversed = true"},
                {1, "address = 0x52\nmux_address = 0x70\nmux_channel = 0"},
                {2, "address = 0x52\nmux_address = 0x70\nmux_channel = 1"},
                {3, "address = 0x52\nmux_address = 0x71\nmux_channel = 1\nbrushless = false"}});
    const ConfigResult r = parse_config_string(text);
    INFO(r.error());
    REQUIRE(r.ok());
    const DaemonConfig& c = *r.config;
    CHECK(c.i2c.device == "/dev/i2c-3");
    CHECK(c.i2c.timeout_ms == 200u);
    CHECK(c.i2c.retries == 2u);
    CHECK(c.spi.device == "/dev/spidev1.0");
    CHECK(c.spi.spi.speed_hz == 1000000);
    CHECK(c.spi.spi.byte_delay_us == 20);
    CHECK(c.spi.teensy.retry.max_busy_retries == 5);
    CHECK(c.spi.teensy.retry.busy_delay_us == 500);
    CHECK(c.spi.teensy.limits.servo_count == 2);
    CHECK(c.spi.teensy.limits.distance_sensor_count == 6);
    CHECK(c.control.loop_rate_hz == 0);
    CHECK(c.control.status_reads_per_tick == 8);
    CHECK(c.control.command_timeout_ms == 250);
    CHECK(c.control.arming_delay_ms == 0);
    CHECK(c.control.budget_policy == BudgetPolicy::Reject);
    REQUIRE(c.gpio.kill_switch);
    CHECK(c.gpio.kill_switch->chip == "gpiochip1");
    CHECK(c.gpio.kill_switch->offset == 17u);
    CHECK(c.gpio.kill_switch->name.empty());
    CHECK(c.gpio.kill_switch->active_low);
    REQUIRE(c.gpio.kill_output);
    CHECK(c.gpio.kill_output->chip == "gpiochip0");
    CHECK(c.gpio.kill_output->name == "KILL");
    CHECK_FALSE(c.gpio.kill_output->offset);
    CHECK_FALSE(c.gpio.kill_output->active_low);
    CHECK(c.gpio.scl->name == "GPIO3");
    CHECK(c.recovery.enabled);
    CHECK(c.recovery.attempts == 5);
    CHECK(c.recovery.backoff_ms == 50);
    CHECK(c.recovery.driver_id == "fe804000.i2c");
    CHECK(c.recovery.device_wait_ms == 2000);
    CHECK(c.mixing[0][0] == 0.5);
    CHECK(c.mixing[7][5] == -1.0);
    CHECK(c.thrusters[0].mt == 0x54);
    CHECK(c.thrusters[0].variant == Variant::Legacy);
    CHECK(c.thrusters[0].info == 7);
    CHECK(c.thrusters[0].reversed);
    REQUIRE(c.thrusters[2].mux);
    CHECK(c.thrusters[2].mux->addr7 == 0x70);
    CHECK(c.thrusters[2].mux->channel == 1);
    CHECK(c.thrusters[3].mux->addr7 == 0x71);
    CHECK(validate_thruster_set(c.thrusters).empty());

    const SafetyConfig s = safety_config(c);
    CHECK(s.arming_delay_ns == 0);
    CHECK(s.command_timeout_ns == 250'000'000ull);
}

TEST_CASE("the shipped example file is valid, with and without its optional settings") {
    std::ifstream f(CARACARA_EXAMPLE_CONFIG);
    REQUIRE(f);
    std::stringstream ss;
    ss << f.rdbuf();
    const std::string text = ss.str();

    const ConfigResult plain = parse_config_file(CARACARA_EXAMPLE_CONFIG);
    INFO(plain.error());
    REQUIRE(plain.ok());
    CHECK(plain.config->mixing == default_mix_matrix());
    CHECK(plain.config->thrusters[7].mt == 0x62);

    // Every "#: " example setting must be valid too.
    std::string enabled;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);)
        enabled += (line.rfind("#: ", 0) == 0 ? line.substr(3) : line) + "\n";
    const ConfigResult all = parse_config_string(enabled, "example with options");
    INFO(all.error());
    REQUIRE(all.ok());
    CHECK(all.config->recovery.enabled);
    CHECK(all.config->gpio.kill_switch);
    CHECK(all.config->thrusters[7].mux);
}

TEST_CASE("a missing file is reported with its path") {
    const ConfigResult r = parse_config_file("/nonexistent/caracarad.toml");
    CHECK_FALSE(r.ok());
    CHECK_THAT(r.error(), Catch::StartsWith("/nonexistent/caracarad.toml: cannot read"));
}

TEST_CASE("a TOML syntax error is reported with its line") {
    const ConfigResult r = parse_config_string("[control]\nloop_rate_hz = = 5\n", "my.toml");
    CHECK_FALSE(r.ok());
    CHECK_THAT(r.error(), Catch::StartsWith("my.toml: line 2"));
}

TEST_CASE("unknown keys are refused, with a suggestion for near misses") {
    check_error("[control]\nlop_rate_hz = 50\n",
                "unknown key 'control.lop_rate_hz'; did you mean 'control.loop_rate_hz'? (line 2)");
    check_error("[contrl]\n", "unknown key 'contrl'; did you mean 'control'?");
    check_error("[blinkenlights]\n", "unknown key 'blinkenlights'; known keys: i2c, spi, thruster");
    check_error("[i2c]\nspeed = 1\n", "unknown key 'i2c.speed'");
    check_error("[spi]\nmode = 0\n", "unknown key 'spi.mode'");
    check_error("[mixing]\nmatrx = []\n", "unknown key 'mixing.matrx'; did you mean 'mixing.matrix'?");
    check_error("[gpio]\nkill = { line = 1 }\n", "unknown key 'gpio.kill'");
    check_error("[gpio]\nkill_switch = { line = 1, pin = 2 }\n", "unknown key 'gpio.kill_switch.pin'");
    check_error("[recovery]\nenable = true\n", "unknown key 'recovery.enable'; did you mean 'recovery.enabled'?");
    check_error(thrusters({{4, "adress = 0x5C"}}), "unknown key 'thruster[4].adress'; did you mean 'thruster[4].address'?");
    // [sim] belongs to caracara-sim and is accepted as is.
    CHECK(parse_config_string("[sim]\nrealistic_timing = true\n").ok());
}

TEST_CASE("sections must be tables") {
    check_error("control = 5\n", "control: must be a table, got 5");
    check_error("[gpio]\nkill_switch = \"GPIO17\"\n", "gpio.kill_switch: must be a table, got \"GPIO17\"");
    check_error("thruster = 5\n", "thruster: must be an array of tables ([[thruster]] sections), got 5");
}

TEST_CASE("[control] values are validated, naming the key") {
    check_error("[control]\nloop_rate_hz = 5000\n",
                "control.loop_rate_hz: must be between 0 and 1000 (0 = as fast as the bus allows), got 5000 (line 2)");
    check_error("[control]\nloop_rate_hz = -1\n", "control.loop_rate_hz: must be between 0 and 1000");
    check_error("[control]\nloop_rate_hz = \"50\"\n", "control.loop_rate_hz: must be an integer, got \"50\"");
    check_error("[control]\nloop_rate_hz = 50.5\n", "control.loop_rate_hz: must be an integer, got 50.5");
    check_error("[control]\nstatus_reads_per_tick = 0\n", "control.status_reads_per_tick: must be between 1 and 8, got 0");
    check_error("[control]\nstatus_reads_per_tick = 9\n", "control.status_reads_per_tick: must be between 1 and 8, got 9");
    check_error("[control]\ncommand_timeout_ms = 5\n", "control.command_timeout_ms: must be between 10 and 60000, got 5");
    check_error("[control]\narming_delay_ms = 60001\n", "control.arming_delay_ms: must be between 0 and 60000, got 60001");
    check_error("[control]\nbudget_policy = \"clip\"\n",
                "control.budget_policy: must be \"scale\" or \"reject\", got \"clip\"");
    check_error("[control]\nbudget_policy = 1\n", "control.budget_policy: must be a string, got 1");
}

TEST_CASE("[i2c] and [spi] values are validated, naming the key") {
    check_error("[i2c]\ndevice = \"i2c-1\"\n", "i2c.device: must be an absolute path, got \"i2c-1\"");
    check_error("[i2c]\ndevice = \"\"\n", "i2c.device: must not be empty");
    check_error("[i2c]\nclock_hz = 10\n", "i2c.clock_hz: must be between 1000 and 3400000, got 10");
    check_error("[i2c]\ntimeout_ms = 5\n", "i2c.timeout_ms: must be between 10 and 60000, got 5");
    check_error("[i2c]\nretries = 17\n", "i2c.retries: must be between 0 and 16, got 17");
    check_error("[spi]\ndevice = 5\n", "spi.device: must be a string, got 5");
    check_error("[spi]\nspeed_hz = 0\n", "spi.speed_hz: must be between 1000 and 50000000, got 0");
    check_error("[spi]\nper_byte_delay_us = 20000\n", "spi.per_byte_delay_us: must be between 0 and 10000, got 20000");
    check_error("[spi]\nbusy_retries = 256\n", "spi.busy_retries: must be between 0 and 255, got 256");
    check_error("[spi]\nbusy_delay_us = -1\n", "spi.busy_delay_us: must be between 0 and 1000000, got -1");
    check_error("[spi]\nservos = 300\n", "spi.servos: must be between 0 and 256 (ids are uint8), got 300");
    check_error("[spi]\ndistance_sensors = -1\n", "spi.distance_sensors: must be between 0 and 256");
    check_error("[spi]\nfitted = 1\n", "spi.fitted: must be true or false");
    check_error("[spi]\nsilence_ms = 5\n", "spi.silence_ms: must be between 10 and 60000, got 5");
    check_error("[spi]\nsilence_ms = 600000\n", "spi.silence_ms: must be between 10 and 60000, got 600000");
}

TEST_CASE("[spi] silence_ms must outlast what an answering Teensy takes: two loop periods and the busy resends") {
    // 50 Hz: 40 ms of polling; 10 busy resends of 200 us: 2 ms.
    check_error("[spi]\nsilence_ms = 42\n",
                "spi.silence_ms: TeensySilenceTooShort: 42 ms is within what an answering Teensy may take (two loop "
                "periods and the busy resends: 42 ms)");
    CHECK(parse_config_string("[spi]\nsilence_ms = 43\n").ok());
    // A slower loop and longer busy resends need a longer silence.
    check_error("[control]\nloop_rate_hz = 10\n[spi]\nsilence_ms = 150\n", "TeensySilenceTooShort");
    check_error("[spi]\nbusy_retries = 100\nbusy_delay_us = 10000\nsilence_ms = 200\n",
                "TeensySilenceTooShort: 200 ms");
    // Unset, it follows the loop and the busy resends: ten periods, at least 200 ms and twice
    // what an answer may take.
    CHECK(parse_config_string("[control]\nloop_rate_hz = 1\n").config->spi.silence_ms == 10000u);
    CHECK(parse_config_string("[control]\nloop_rate_hz = 0\n").config->spi.silence_ms == 200u);
    CHECK(parse_config_string("[spi]\nbusy_retries = 100\nbusy_delay_us = 10000\n").config->spi.silence_ms ==
          2080u);
    // A file refused for it changes nothing: no config comes out.
    CHECK_FALSE(parse_config_string("[spi]\nsilence_ms = 20\n").config);
    const ConfigResult r = parse_config_string("[spi]\nfitted = false\nsilence_ms = 500\n");
    REQUIRE(r.ok());
    CHECK_FALSE(r.config->spi.fitted);
    CHECK(r.config->spi.silence_ms == 500u);
}

TEST_CASE("[[thruster]] values are validated, naming the thruster and key") {
    check_error(thrusters({{3, "address = 0x53"}}),
                "thruster[3].address: 0x53 is a read address byte; must be even (the write byte, e.g. 0x52)");
    check_error(thrusters({{0, "address = 0x08"}}), "thruster[0].address: 0x08 is a reserved I2C address");
    check_error(thrusters({{0, "address = 0xF0"}}), "thruster[0].address: 0xF0 is a reserved I2C address");
    check_error(thrusters({{0, "address = 0x152"}}), "thruster[0].address: must be an 8-bit address byte (MT), got 0x152");
    check_error(thrusters({{0, "address = \"0x52\""}}), "thruster[0].address: must be an integer, got \"0x52\"");
    check_error("[[thruster]]\nvariant = \"seabotix\"\n" + thrusters({}, 7), "thruster[0].address: missing");
    check_error(thrusters({{2, "variant = \"aveox\""}}),
                "thruster[2].variant: must be \"seabotix\" or \"legacy\", got \"aveox\"");
    check_error(thrusters({{2, "info = 256"}}), "thruster[2].info: must be between 0 and 255, got 256");
    check_error(thrusters({{2, "reversed = \"yes\""}}), "thruster[2].reversed: must be true or false, got \"yes\"");
    check_error(thrusters({{1, "mux_address = 0x70"}}),
                "thruster[1].mux_channel: missing: mux_address and mux_channel go together");
    check_error(thrusters({{1, "mux_channel = 2"}}),
                "thruster[1].mux_address: missing: mux_address and mux_channel go together");
    check_error(thrusters({{1, "mux_address = 0xE0\nmux_channel = 0"}}),
                "thruster[1].mux_address: 0xE0 looks like an 8-bit address byte; use the 7-bit address 0x70");
    check_error(thrusters({{1, "mux_address = 0x6F\nmux_channel = 0"}}),
                "thruster[1].mux_address: must be a 7-bit PCA9544A address between 0x70 and 0x77");
    check_error(thrusters({{1, "mux_address = 0x70\nmux_channel = 4"}}),
                "thruster[1].mux_channel: must be between 0 and 3, got 4");
}

TEST_CASE("there must be exactly eight thrusters") {
    check_error(thrusters({}, 7), "thruster: expected exactly 8 [[thruster]] sections (motors 0..7), got 7");
    check_error(thrusters({}, 9), "got 9");
}

TEST_CASE("address clashes name both thrusters") {
    check_error(thrusters({{5, "address = 0x52"}}),
                "thruster[5].address: 0x52 is also the address of thruster[0]; both are on the main bus");
    check_error(thrusters({{2, "address = 0x50\nmux_address = 0x70\nmux_channel = 1"},
                           {6, "address = 0x50\nmux_address = 0x70\nmux_channel = 1"}}),
                "thruster[6].address: 0x50 is also the address of thruster[2]; both are behind mux 0x70 channel 1");
    // A thruster on the main bus clashes with a same-address one behind any mux channel.
    const std::string err = errors_of(thrusters({{0, "address = 0x52\nmux_address = 0x70\nmux_channel = 1"},
                                                 {5, "address = 0x52"}}));
    CHECK_THAT(err, Catch::Contains("thruster[5].address: 0x52 is also the address of thruster[0]") &&
                        Catch::Contains("thruster[5] is on the main bus"));
    // A thruster at the multiplexer's own address.
    check_error(thrusters({{1, "address = 0x52\nmux_address = 0x70\nmux_channel = 1"}, {4, "address = 0xE0"}}),
                "thruster[4].address: 0xE0 (7-bit 0x70) is the address of the multiplexer used by thruster[1]");
    // Same address on different channels or different muxes is the point of a mux.
    CHECK(parse_config_string(thrusters({{0, "address = 0x52\nmux_address = 0x70\nmux_channel = 0"},
                                         {1, "address = 0x52\nmux_address = 0x70\nmux_channel = 1"},
                                         {2, "address = 0x52\nmux_address = 0x71\nmux_channel = 1"}}))
              .ok());
}

TEST_CASE("[mixing] matrix is validated, naming the row and column") {
    const std::string row = "[0, 0, 0, 0, 0, 0]";
    auto matrix = [&](int rows, const std::string& special = "", int at = -1) {
        std::string m = "[mixing]\nmatrix = [";
        for (int i = 0; i < rows; ++i)
            m += (i ? ", " : "") + (i == at ? special : row);
        return m + "]\n";
    };
    check_error(matrix(7), "mixing.matrix: must be an array of 8 rows (one per motor), got 7 rows");
    check_error("[mixing]\nmatrix = 1\n", "mixing.matrix: must be an array of 8 rows (one per motor), got 1");
    check_error(matrix(8, "[0, 0, 0, 0, 0]", 2),
                "mixing.matrix[2]: must be an array of 6 numbers (x, y, z, yaw, pitch, roll), got 5 values");
    check_error(matrix(8, "[0, 0, 0, 2, 0, 0]", 4),
                "mixing.matrix[4][3] (motor 4, yaw): must be a number between -1 and 1, got 2");
    check_error(matrix(8, "[0, 0, 0, 0, 0, nan]", 1), "mixing.matrix[1][5] (motor 1, roll): must be a number between -1 and 1, got nan");
    check_error(matrix(8, "[0, \"a\", 0, 0, 0, 0]", 0), "mixing.matrix[0][1] (motor 0, y): must be a number, got \"a\"");
    const ConfigResult ok = parse_config_string(matrix(8, "[1, -1, 0.25, 0, 0, 0]", 3));
    REQUIRE(ok.ok());
    CHECK(ok.config->mixing[3][2] == 0.25);
}

TEST_CASE("[gpio] lines are validated, naming the key") {
    check_error("[gpio]\nkill_switch = { chip = \"gpiochip0\" }\n",
                "gpio.kill_switch.line: missing (a line name string or an offset integer)");
    check_error("[gpio]\nkill_output = { line = -1 }\n",
                "gpio.kill_output.line: must be a line offset between 0 and 65535, got -1");
    check_error("[gpio]\nkill_output = { line = 1.5 }\n",
                "gpio.kill_output.line: must be a line name string or an offset integer, got 1.5");
    check_error("[gpio]\nkill_output = { line = \"\" }\n", "gpio.kill_output.line: must not be empty");
    check_error("[gpio]\npower_off_output = { chip = \"\", line = 3 }\n", "gpio.power_off_output.chip: must not be empty");
    check_error("[gpio]\nkill_switch = { line = 3, active_low = 1 }\n",
                "gpio.kill_switch.active_low: must be true or false, got 1");
    check_error("[gpio]\nscl = { line = 3 }\n", "gpio.sda: missing: gpio.scl and gpio.sda go together");
    check_error("[gpio]\nsda = { line = 2 }\n", "gpio.scl: missing: gpio.scl and gpio.sda go together");
    check_error("[gpio]\nkill_switch = { line = 17 }\nkill_output = { line = 17 }\n",
                "gpio.kill_output: line 17 on gpiochip0 is also used by gpio.kill_switch");
    check_error("[gpio]\nscl = { line = \"GPIO3\" }\nsda = { line = \"GPIO3\" }\n",
                "gpio.sda: line \"GPIO3\" on gpiochip0 is also used by gpio.scl");
    // The same offset on different chips is a different line.
    CHECK(parse_config_string("[gpio]\nkill_switch = { line = 17 }\nkill_output = { chip = \"gpiochip1\", line = 17 }\n")
              .ok());
}

TEST_CASE("[recovery] values are validated, naming the key") {
    check_error("[recovery]\nattempts = 0\n", "recovery.attempts: must be between 1 and 10, got 0");
    check_error("[recovery]\nbackoff_ms = 70000\n", "recovery.backoff_ms: must be between 0 and 60000, got 70000");
    check_error("[recovery]\nunbind_path = \"unbind\"\n", "recovery.unbind_path: must be an absolute path");
    check_error("[recovery]\nbind_path = \"\"\n", "recovery.bind_path: must not be empty");
    check_error("[recovery]\ndriver_id = \"a/b\"\n",
                "recovery.driver_id: must be a device name such as \"fe804000.i2c\", got \"a/b\"");
    check_error("[recovery]\ndevice_wait_ms = -5\n", "recovery.device_wait_ms: must be between 0 and 60000, got -5");
    check_error("[recovery]\nenabled = \"yes\"\n", "recovery.enabled: must be true or false");
    check_error("[recovery]\nenabled = true\n", "recovery.enabled: bus recovery needs gpio.scl and gpio.sda");
}

TEST_CASE("[realtime] values are validated, naming the key; the loop stays above the workers") {
    const ConfigResult d = parse_config_string("");
    REQUIRE(d.ok());
    CHECK(d.config->realtime.enabled);
    CHECK(d.config->realtime.loop_priority > d.config->realtime.bus_priority);
    CHECK(d.config->realtime.loop_priority > d.config->realtime.teensy_priority);
    const ConfigResult r = parse_config_string("[realtime]\npolicy = \"rr\"\nloop_priority = 20\nbus_priority = 10\n"
                                               "teensy_priority = 5\nlock_memory = false\nenabled = false\n");
    REQUIRE(r.ok());
    CHECK(r.config->realtime.policy == SchedPolicy::RoundRobin);
    CHECK(r.config->realtime.loop_priority == 20);
    CHECK(r.config->realtime.bus_priority == 10);
    CHECK(r.config->realtime.teensy_priority == 5);
    CHECK_FALSE(r.config->realtime.lock_memory);
    CHECK_FALSE(r.config->realtime.enabled);
    check_error("[realtime]\npolicy = \"deadline\"\n", "realtime.policy: must be \"fifo\" or \"rr\", got \"deadline\"");
    check_error("[realtime]\nloop_priority = 50\n",
                "realtime.loop_priority: must be between 1 and 49 (below the kernel's interrupt threads at 50), got 50");
    check_error("[realtime]\nbus_priority = 0\n", "realtime.bus_priority: must be between 1 and 49");
    check_error("[realtime]\nbus_priority = 40\n",
                "realtime.bus_priority: must be below realtime.loop_priority (40): a kill on the loop preempts the wire");
    check_error("[realtime]\nloop_priority = 10\n", "realtime.teensy_priority: must be below realtime.loop_priority (10)");
    check_error("[realtime]\nlock_memory = 1\n", "realtime.lock_memory: must be true or false");
    check_error("[realtime]\nniceness = 1\n", "realtime.niceness");
}

TEST_CASE("every problem in a file is reported at once, prefixed with the source") {
    const ConfigResult r =
        parse_config_string("[control]\nloop_rate_hz = 5000\nbudget_policy = \"x\"\n[i2c]\nretries = 99\n", "vehicle.toml");
    REQUIRE_FALSE(r.ok());
    REQUIRE(r.errors.size() == 3);
    for (const std::string& e : r.errors)
        CHECK_THAT(e, Catch::StartsWith("vehicle.toml: "));
    CHECK_THAT(r.error(), Catch::Contains("i2c.retries") && Catch::Contains("control.loop_rate_hz") &&
                              Catch::Contains("control.budget_policy"));
}

// In the manner of a fuzzer: the shipped example with every option enabled, one to three of its
// values replaced by edge values of every TOML type. Whatever comes out, the parser neither
// throws nor trips the sanitizers, every message of a refused file names its key, and a value of
// the wrong type or out of any integer key's range is refused, with its key and line, instead of
// being wrapped or truncated.
TEST_CASE("mutated values: a refused file names each bad key and line, nothing is wrapped or truncated") {
    std::ifstream f(CARACARA_EXAMPLE_CONFIG);
    REQUIRE(f);
    std::vector<std::string> lines;
    for (std::string line; std::getline(f, line);)
        lines.push_back(line.rfind("#: ", 0) == 0 ? line.substr(3) : line);
    std::vector<size_t> keyed; // lines "key = value" outside the matrix
    for (size_t i = 0; i < lines.size(); ++i)
        if (!lines[i].empty() && std::isalpha(static_cast<unsigned char>(lines[i][0])) &&
            lines[i].find(" = ") != std::string::npos && lines[i].find('[') == std::string::npos)
            keyed.push_back(i);
    REQUIRE(keyed.size() > 20);

    struct Edge {
        const char* text;
        enum { Int, OutOfRange, Float, String, Other } kind;
    };
    const Edge edges[] = {
        {"0", Edge::Int}, {"1", Edge::Int}, {"255", Edge::Int}, {"65536", Edge::Int}, {"4294967295", Edge::Int},
        {"-1", Edge::OutOfRange}, {"4294967296", Edge::OutOfRange}, {"9223372036854775807", Edge::OutOfRange},
        {"-9223372036854775808", Edge::OutOfRange}, {"0.5", Edge::Float}, {"-0.0", Edge::Float},
        {"1e308", Edge::Float}, {"-1e308", Edge::Float}, {"nan", Edge::Float}, {"inf", Edge::Float},
        {"-inf", Edge::Float}, {"1e-300", Edge::Float}, {"\"\"", Edge::String}, {"\"x\"", Edge::String},
        {"\"/dev/null\"", Edge::String}, {"true", Edge::Other}, {"false", Edge::Other}, {"[]", Edge::Other},
        {"[1, 2]", Edge::Other}, {"{}", Edge::Other}, {"{ chip = 7 }", Edge::Other},
        {"1979-05-27T07:32:00Z", Edge::Other},
    };
    const unsigned seed = 20261121;
    INFO("seed " << seed);
    std::mt19937 rng(seed);
    auto pick = [&](size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(rng); };
    auto is_integer = [](const std::string& v) {
        return !v.empty() && v.find_first_not_of("0123456789abcdefABCDEFx") == std::string::npos &&
               std::isdigit(static_cast<unsigned char>(v[0]));
    };
    int accepted = 0, refused = 0;
    for (int round = 0; round < 3000; ++round) {
        std::vector<std::string> text = lines;
        // line -> its key, for replacements no key of that kind may take
        std::map<size_t, std::string> must_refuse;
        for (size_t k = 1 + pick(3); k > 0; --k) {
            const size_t at = keyed[pick(keyed.size())];
            const size_t eq = lines[at].find(" = ");
            const std::string key = lines[at].substr(0, eq);
            const std::string old_value = lines[at].substr(eq + 3); // the example's own value and type
            const Edge& e = edges[pick(std::size(edges))];
            text[at] = key + " = " + e.text;
            const bool old_int = is_integer(old_value);
            const bool old_str = old_value.front() == '"';
            if ((old_int && (e.kind == Edge::OutOfRange || e.kind == Edge::Float || e.kind == Edge::String)) ||
                (old_str && e.kind != Edge::String))
                must_refuse[at] = key;
            else
                must_refuse.erase(at);
        }
        std::string joined;
        for (auto& l : text)
            joined += l + "\n";
        INFO("config:\n" << joined);
        const ConfigResult r = parse_config_string(joined);
        if (r.ok()) {
            ++accepted;
            CHECK(must_refuse.empty());
            continue;
        }
        ++refused;
        REQUIRE_FALSE(r.errors.empty());
        for (const auto& err : r.errors)
            CHECK_THAT(err, Catch::Contains(": "));
        for (const auto& [at, key] : must_refuse)
            CHECK_THAT(r.error(), Catch::Contains(key + ": ") && Catch::Contains("(line " + std::to_string(at + 1) + ")"));
    }
    // Both outcomes were reached, so the checks above saw both kinds of result.
    CHECK(accepted > 20);
    CHECK(refused > 1000);
}

TEST_CASE("non-ASCII text is refused outside comments, before toml++ sees it (fuzz_config regression)") {
    // toml++ 3.3 hit __builtin_unreachable on these: a key, a value's tail, the line after a
    // line-ending backslash in a multi-line string.
    CHECK(errors_of("\xd0\xbb") == "line 1, column 1: non-ASCII byte 0xd0 outside a comment (keys and values in this "
                                   "file are ASCII)");
    CHECK_THAT(errors_of("[control]\nloop_rate_hz = 50\xc2\xb0\n"), Catch::Contains("line 2, column 18: non-ASCII"));
    CHECK_THAT(errors_of("[spi]\ndevice = \"\"\"\\\n\xc2\xa7/dev/spidev0.0\"\"\"\n"), Catch::Contains("line 3, column 1"));
    // Strings hide neither a '#' nor an escaped quote from the guard.
    CHECK_THAT(errors_of("[spi]\ndevice = \"/dev/x#\xc3\xa9\"\n"), Catch::Contains("line 2, column 18"));
    CHECK_THAT(errors_of("[spi]\ndevice = \"/dev/\\\"#\" \xc3\xa9\n"), Catch::Contains("line 2, column 21"));
    CHECK_THAT(errors_of("[spi]\ndevice = '/dev/#'\xc3\xa9\n"), Catch::Contains("line 2, column 18"));
    CHECK(parse_config_string("[spi]\ndevice = '''/dev/#\n\xc3\xa9'''\n").error().find("line 3, column 1") !=
          std::string::npos);
    // Comments may say anything, also after strings with quotes just inside their delimiters.
    const ConfigResult r = parse_config_string("# 20 \xc2\xb0" "C, \xc2\xb5s, \xd0\xbb\n[recovery]  # \xc3\xa9\n"
                                               "driver_id = \"\"\"x\"\"\"\"\"  # \xc2\xa7\n"
                                               "unbind_path = '''/a''''' # \xc2\xa7\n");
    INFO(r.error());
    REQUIRE(r.ok());
    CHECK(r.config->recovery.driver_id == "x\"\"");
    CHECK(r.config->recovery.unbind_path == "/a''");
}
