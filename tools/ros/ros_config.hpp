// caracara-ros's settings: the ROS namespace and domain, the Range layout (Humble or Jazzy),
// whether commands are taken, the frames and their convention, the network DDS may use and the
// SROS2 enclave that secures it. Read from a TOML file
// (/etc/caracara/ros.toml; docs/ros2.md lists every key) and the command line.
#pragma once

#include "core/frames.hpp"
#include "core/vehicle_geometry.hpp"
#include "drivers/sdbus/sdbus.hpp"
#include "tools/ros/ros_conventions.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace caracara::ros {

// Where a sensor sits on the vehicle, for /tf_static: its frame's name, its position in metres
// and its orientation in radians (URDF's rpy: roll about x, pitch about y, yaw about z, fixed
// axes) in the base frame, REP 103's body FLU (x forward, y left, z up).
struct SensorMount {
    std::string frame;
    frames::Vec3 xyz, rpy;
};

// Where caracara-ros and caracaractl export read the settings unless told (a missing one: the defaults).
inline constexpr const char* kDefaultConfigPath = "/etc/caracara/ros.toml";
// Where the vehicle's description is (wrench_units = "newton"): the daemon's own file.
inline constexpr const char* kDefaultVehicleConfigPath = "/etc/caracara/caracarad.toml";

struct RosConfig {
    std::string ros_namespace = "/caracara";
    uint32_t domain_id = 0;           // ROS_DOMAIN_ID, else 0; the file's domain_id wins
    RangeLayout range_layout = RangeLayout::Humble; // also ros_discovery_info's Gid: 24 bytes, Jazzy's 16
    bool range_layout_given = false; // else the peers' distro (DistroDetector) and the Range subscribers' (RangeSubscribers)
    bool commands = false;            // Wrench and per-thruster commands; kill is always taken
    WrenchUnits wrench_units = WrenchUnits::Fraction;
    // Newton: the description read from this caracarad.toml ([vehicle], [[thruster]] position and
    // direction), the one caracara-sim reads too.
    std::string vehicle_config = kDefaultVehicleConfigPath;
    VehicleGeometry vehicle;
    // An SROS2 enclave directory (keystore/enclaves/<path>): DDS Security on, "" = off.
    std::string security;
    // Where libdds_security_{auth,ac,crypto}.so are: Debian's libddsc0debian directory, found at build time.
    std::string security_plugins = CARACARA_DDS_SECURITY_PLUGINS;
    // Commands with no security on an interface other than loopback: refused unless this says so.
    bool insecure_commands = false;
    // The one network interface DDS uses: loopback until the config names the tether ("" = Cyclone picks).
    std::string interface = "lo";
    std::string world_frame = kDefaultWorldFrame;
    std::string base_frame = kDefaultBaseFrame;
    // The Imu's and /tf's orientation: REP 103 / 145 (base_link FLU in odom ENU), or NED / FRD
    // under the frame names with _ned / _frd (ros_conventions.hpp).
    frames::WorldFrame frame_convention = frames::WorldFrame::EnuFlu;
    // Off for a vehicle whose localization publishes odom -> base_link: two publishers of one
    // transform make tf2 jump between them.
    bool publish_odom_tf = true;
    float range_min_m = 0.0f, range_max_m = 65.535f, range_fov_rad = 0.0f;
    // imu, /tf and joint_states go out at this rate whether their values change or not, as a ROS
    // driver's do (tf2 and robot_localization wait for a steady stream).
    double sensor_rate_hz = kDaemonTelemetryRateHz;
    // [ros.imu] and [[ros.range]] (one per distance sensor, in the Teensy's order): by default at
    // the base frame's origin, facing forward; a sensor the config does not list gets that too.
    SensorMount imu{kDefaultImuFrame, {}, {}};
    std::vector<SensorMount> ranges;
    caracara::dbus::BusChoice bus;
};

// Reads `path` into `config`; returns "" or what is wrong with the file (named key and value).
std::string load_config(const std::string& path, RosConfig& config);

// "" when the settings may run, else why not: commands on, security off, on an interface that is not
// loopback (`loopback`: what is_loopback(config.interface) said) and no insecure_commands = true.
std::string commands_refusal(const RosConfig& config, bool loopback);

// Whether `interface` is a loopback interface of this machine ("" is not: Cyclone picks any).
bool is_loopback(const std::string& interface);
// Distance sensor i's mount: the config's, else range_i at the origin facing forward.
SensorMount range_mount(const RosConfig& config, std::size_t i);
// Every mount /tf_static carries, under the base frame itself (REP 103's body FLU, also with
// frame_convention = "ned"): the IMU, then each distance sensor, the config's and up to `ranges`
// the Teensy reports.
std::vector<SensorMount> sensor_mounts(const RosConfig& config, std::size_t ranges);
// A mount's rotation: URDF's rpy (fixed axes x, y, z) is the Z-Y-X Euler rotation yaw, pitch, roll.
frames::Quaternion mount_rotation(const SensorMount& m);

// The ROS topic name under the namespace ("state" -> "/caracara/state"; "/diagnostics" stays).
std::string ros_topic(const RosConfig& config, const std::string& name);

} // namespace caracara::ros
