// The command topics: kill (std_msgs/Empty, always taken), and when the config turns commands
// on, cmd_wrench (geometry_msgs/Wrench in REP 103's body FLU frame -> SetMotion) and cmd_thrust (std_msgs/Float64MultiArray,
// 8 values -1..1 -> SetThrust). Each remote writer of a motion topic is a Pilot with its own D-Bus
// connection; a writer that goes away (unmatched: it left, its lease expired) has its
// connection closed, which the daemon takes as a client that left. Cyclone's listener threads
// only wake the event loop (an eventfd); the samples are taken on the loop, kills first.
#pragma once

#include "tools/ros/dds_participant.hpp"
#include "tools/ros/pilot.hpp"

#include <functional>
#include <map>
#include <memory>

namespace caracara::ros {

class CommandSubscriber {
public:
    // kill(): send Kill on any connection (the daemon takes it from every client).
    CommandSubscriber(sd_event* event, DdsParticipant& dds, const RosConfig& config, std::function<void()> kill);
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
    Pilot* pilot(dds_instance_handle_t writer);

    sd_event* event_;
    const RosConfig& config_;
    std::function<void()> kill_;
    int wake_fd_ = -1;
    caracara::SourcePtr wake_;
    dds_listener_t* listener_ = nullptr;
    dds_entity_t kill_reader_ = 0, wrench_reader_ = 0, thrust_reader_ = 0;
    std::map<dds_instance_handle_t, std::unique_ptr<Pilot>> pilots_;
};

} // namespace caracara::ros
