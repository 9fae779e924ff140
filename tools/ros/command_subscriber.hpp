// The command topics: kill (std_msgs/Empty, always taken), and when the config turns commands
// on, cmd_wrench (geometry_msgs/Wrench in REP 103's body FLU frame -> SetMotion) and cmd_thrust (std_msgs/Float64MultiArray,
// 8 values -1..1 -> SetThrust). Each remote writer of a motion topic is a Pilot with its own D-Bus
// connection; a writer that goes away (unmatched: it left, its lease expired) has its
// connection closed, which the daemon takes as a client that left. One writer commands at a
// time: the first that sends holds the vehicle until it stops for the command timeout or leaves;
// the others' samples are refused (not-holder), logged with their GID and counted in the
// CommandRecord. Cyclone's listener threads only wake the event loop (an eventfd); the samples
// are taken on the loop, kills first.
#pragma once

#include "tools/ros/dds_participant.hpp"
#include "tools/ros/spoken_distro.hpp"
#include "tools/ros/pilot.hpp"

#include <functional>
#include <map>
#include <memory>

namespace caracara::ros {

class CommandSubscriber {
public:
    // kill(): send Kill on any connection (the daemon takes it from every client).
    CommandSubscriber(sd_event* event, DdsParticipant& dds, const RosConfig& config, CommandRecord& record,
                      const SpokenDistro& distro,
                      std::function<void()> kill);
    ~CommandSubscriber();
    CommandSubscriber(const CommandSubscriber&) = delete;
    CommandSubscriber& operator=(const CommandSubscriber&) = delete;

private:
    static int on_wake(sd_event_source* s, int fd, uint32_t revents, void* userdata);
    static void on_dds(dds_entity_t reader, void* arg);
    static void on_matched(dds_entity_t reader, const dds_publication_matched_status_t status, void* arg);
    void release(); // the listener off the readers, the wake-up closed; the destructor's, and a failed constructor's
    void drain();
    void take_kills();
    void take_wrenches();
    void take_thrusts();
    void drop_unmatched();
    // The writer's Pilot if it may command now (it holds the vehicle, or takes it: none holds it);
    // null after logging and counting the refusal.
    Pilot* commanding(dds_entity_t reader, dds_instance_handle_t writer, const char* topic);
    Pilot* pilot(dds_instance_handle_t writer);
    // The writer's GID as `ros2 topic info -v` prints it (dotted hex, the distro's Gid size).
    const std::string& gid(dds_entity_t reader, dds_instance_handle_t writer);

    sd_event* event_;
    const RosConfig& config_;
    const SpokenDistro& distro_; // a GID is printed in its Gid size
    std::function<void()> kill_;
    int wake_fd_ = -1;
    caracara::SourcePtr wake_;
    dds_listener_t* listener_ = nullptr;
    dds_entity_t kill_reader_ = 0, wrench_reader_ = 0, thrust_reader_ = 0;
    std::map<dds_instance_handle_t, std::unique_ptr<Pilot>> pilots_;
    std::map<dds_instance_handle_t, std::string> gids_;
    CommandRecord& record_;
    dds_instance_handle_t holder_ = 0; // the record's holder while record_.holder() names one
    // The writers whose refusal (not-holder) was logged during the current hold: one line each.
    std::map<dds_instance_handle_t, dds_instance_handle_t> told_;
};

} // namespace caracara::ros
