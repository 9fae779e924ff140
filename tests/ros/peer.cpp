// The test peer: a Fast DDS 2.9 participant (a second DDS vendor) whose types fastddsgen made
// from the ROS 2 message definitions as published (msg_to_idl.mjs), never from the project's
// IDL. Modes (samples travel as hex CDR, encapsulation header included, so the test encodes and
// decodes them with @foxglove/rosmsg2-serialization):
//   peer listen SECONDS TOPIC=TYPE...   one JSON line per sample {"topic","cdr","t_ns"}, per
//                                       discovered participant {"participant","user_data"} and
//                                       writer {"writer","type","reliable","transient_local","xcdr1"}
//   peer publish TOPIC TYPE HEX COUNT HZ [hold]   publishes once matched; hold: then sleeps
//   peer roundtrip TYPE HEX             Fast CDR's bytes for the sample the hex decodes to
// TYPE is "pkg/Name"; TOPIC the DDS topic ("rt/caracara/imu"). Participant lease 200 ms, so a
// killed peer is noticed quickly (docs/ros2.md: the lease sets how soon a dead pilot leaves).
#include "ros_h.h"
#include "ros_hPubSubTypes.h"

#include <chrono>
#include <cstdio>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

using namespace eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::SerializedPayload_t;

namespace {

std::mutex out_mutex;

TopicDataType* make_type(const std::string& t) {
    static const std::map<std::string, std::function<TopicDataType*()>> types = {
        {"sensor_msgs/Imu", [] { return new sensor_msgs::msg::dds_::Imu_PubSubType(); }},
        {"sensor_msgs/JointState", [] { return new sensor_msgs::msg::dds_::JointState_PubSubType(); }},
        {"sensor_msgs/Range", [] { return new sensor_msgs::msg::dds_::Range_PubSubType(); }},
        {"diagnostic_msgs/DiagnosticArray", [] { return new diagnostic_msgs::msg::dds_::DiagnosticArray_PubSubType(); }},
        {"std_msgs/Bool", [] { return new std_msgs::msg::dds_::Bool_PubSubType(); }},
        {"std_msgs/String", [] { return new std_msgs::msg::dds_::String_PubSubType(); }},
        {"std_msgs/Empty", [] { return new std_msgs::msg::dds_::Empty_PubSubType(); }},
        {"std_msgs/Float64MultiArray", [] { return new std_msgs::msg::dds_::Float64MultiArray_PubSubType(); }},
        {"geometry_msgs/Wrench", [] { return new geometry_msgs::msg::dds_::Wrench_PubSubType(); }},
        {"tf2_msgs/TFMessage", [] { return new tf2_msgs::msg::dds_::TFMessage_PubSubType(); }},
    };
    const auto it = types.find(t);
    if (it == types.end()) {
        std::fprintf(stderr, "peer: unknown type %s\n", t.c_str());
        std::exit(2);
    }
    return it->second();
}

std::string hex(const SerializedPayload_t& p) {
    static const char d[] = "0123456789abcdef";
    std::string s;
    for (uint32_t i = 0; i < p.length; ++i) {
        s += d[p.data[i] >> 4];
        s += d[p.data[i] & 15];
    }
    return s;
}

SerializedPayload_t unhex(const std::string& h) {
    SerializedPayload_t p(static_cast<uint32_t>(h.size() / 2));
    for (std::size_t i = 0; i + 1 < h.size(); i += 2)
        p.data[i / 2] = static_cast<unsigned char>(std::stoi(h.substr(i, 2), nullptr, 16));
    p.length = static_cast<uint32_t>(h.size() / 2);
    return p;
}

std::string to_hex(TypeSupport& type, void* data) {
    SerializedPayload_t p(type->getSerializedSizeProvider(data)());
    if (!type->serialize(data, &p)) {
        std::fprintf(stderr, "peer: serialize failed\n");
        std::exit(1);
    }
    return hex(p);
}

int64_t now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

class Discovery : public DomainParticipantListener {
public:
    void on_participant_discovery(DomainParticipant*, eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
        if (info.status != eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT)
            return;
        const auto& u = info.info.m_userData;
        std::string s(u.begin(), u.end());
        std::lock_guard l(out_mutex);
        std::printf("{\"participant\":\"%s\",\"user_data\":\"%s\"}\n", info.info.m_participantName.c_str(), s.c_str());
        std::fflush(stdout);
    }
    void on_publisher_discovery(DomainParticipant*, eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
        if (info.status != eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERED_WRITER)
            return;
        const auto& q = info.info.m_qos;
        bool xcdr1 = q.representation.m_value.empty(); // none announced means XCDR1 (DDS-XTypes 7.6.3.1.1)
        for (const auto r : q.representation.m_value)
            xcdr1 = xcdr1 || r == XCDR_DATA_REPRESENTATION;
        std::lock_guard l(out_mutex);
        std::printf("{\"writer\":\"%s\",\"type\":\"%s\",\"reliable\":%s,\"transient_local\":%s,\"xcdr1\":%s}\n",
                    info.info.topicName().c_str(), info.info.typeName().c_str(),
                    q.m_reliability.kind == RELIABLE_RELIABILITY_QOS ? "true" : "false",
                    q.m_durability.kind == TRANSIENT_LOCAL_DURABILITY_QOS ? "true" : "false", xcdr1 ? "true" : "false");
        std::fflush(stdout);
    }
};

class Printer : public DataReaderListener {
public:
    Printer(std::string topic, TypeSupport type) : topic_(std::move(topic)), type_(std::move(type)) {}
    void on_data_available(DataReader* reader) override {
        void* data = type_.create_data();
        SampleInfo info;
        while (reader->take_next_sample(data, &info) == ReturnCode_t::RETCODE_OK) {
            if (!info.valid_data)
                continue;
            const std::string h = to_hex(type_, data);
            std::lock_guard l(out_mutex);
            std::printf("{\"topic\":\"%s\",\"cdr\":\"%s\",\"t_ns\":%lld}\n", topic_.c_str(), h.c_str(),
                        static_cast<long long>(now_ns()));
            std::fflush(stdout);
        }
        type_.delete_data(data);
    }

private:
    std::string topic_;
    TypeSupport type_;
};

DomainParticipant* participant(DomainParticipantListener* listener) {
    DomainParticipantQos q = PARTICIPANT_QOS_DEFAULT;
    q.name("caracara_ros_test_peer");
    q.wire_protocol().builtin.discovery_config.leaseDuration = eprosima::fastrtps::Duration_t(0, 200'000'000);
    q.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(0, 50'000'000);
    const char* domain = std::getenv("ROS_DOMAIN_ID");
    auto* p = DomainParticipantFactory::get_instance()->create_participant(domain ? std::atoi(domain) : 0, q, listener,
                                                                            StatusMask::none());
    if (!p) {
        std::fprintf(stderr, "peer: no participant\n");
        std::exit(1);
    }
    return p;
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2)
        return 2;
    const std::string mode = argv[1];
    if (mode == "roundtrip" && argc == 4) {
        TypeSupport type(make_type(argv[2]));
        void* data = type.create_data();
        SerializedPayload_t p = unhex(argv[3]);
        if (!type->deserialize(&p, data))
            return 1;
        std::printf("%s\n", to_hex(type, data).c_str());
        return 0;
    }
    if (mode == "listen" && argc >= 3) {
        Discovery discovery;
        DomainParticipant* part = participant(&discovery);
        Subscriber* sub = part->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
        std::vector<std::unique_ptr<Printer>> printers;
        for (int i = 3; i < argc; ++i) {
            const std::string a = argv[i];
            const auto eq = a.find('=');
            TypeSupport type(make_type(a.substr(eq + 1)));
            type.register_type(part);
            Topic* topic = part->create_topic(a.substr(0, eq), type.get_type_name(), TOPIC_QOS_DEFAULT);
            DataReaderQos rq = DATAREADER_QOS_DEFAULT;
            rq.reliability().kind = RELIABLE_RELIABILITY_QOS;
            rq.durability().kind = TRANSIENT_LOCAL_DURABILITY_QOS; // a late joiner's view of latched topics
            rq.history().depth = 10;
            rq.type_consistency().representation.m_value.push_back(XCDR_DATA_REPRESENTATION);
            // Volatile writers match a transient-local reader? No: request volatile for them.
            const bool latched = a.find("/state=") != std::string::npos || a.find("/killed=") != std::string::npos ||
                                 a.find("/kill_source=") != std::string::npos;
            if (!latched)
                rq.durability().kind = VOLATILE_DURABILITY_QOS;
            printers.push_back(std::make_unique<Printer>(a.substr(0, eq), type));
            sub->create_datareader(topic, rq, printers.back().get());
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<int>(std::atof(argv[2]) * 1000)));
        part->delete_contained_entities();
        DomainParticipantFactory::get_instance()->delete_participant(part);
        return 0;
    }
    if (mode == "publish" && argc >= 7) {
        DomainParticipant* part = participant(nullptr);
        TypeSupport type(make_type(argv[3]));
        type.register_type(part);
        Topic* topic = part->create_topic(argv[2], type.get_type_name(), TOPIC_QOS_DEFAULT);
        DataWriterQos wq = DATAWRITER_QOS_DEFAULT;
        wq.reliability().kind = RELIABLE_RELIABILITY_QOS;
        wq.durability().kind = VOLATILE_DURABILITY_QOS;
        wq.representation().m_value.push_back(XCDR_DATA_REPRESENTATION);
        DataWriter* w = part->create_publisher(PUBLISHER_QOS_DEFAULT)->create_datawriter(topic, wq);
        void* data = type.create_data();
        SerializedPayload_t p = unhex(argv[4]);
        if (!type->deserialize(&p, data))
            return 1;
        PublicationMatchedStatus s{};
        for (int i = 0; i < 200 && s.current_count == 0; ++i) {
            w->get_publication_matched_status(s);
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
        }
        if (s.current_count == 0) {
            std::fprintf(stderr, "peer: no reader matched %s\n", argv[2]);
            return 1;
        }
        const int count = std::atoi(argv[5]);
        const auto period = std::chrono::microseconds(static_cast<int>(1e6 / std::atof(argv[6])));
        for (int i = 0; i < count; ++i) {
            w->write(data);
            std::printf("{\"sent\":%d,\"t_ns\":%lld}\n", i, static_cast<long long>(now_ns()));
            std::fflush(stdout);
            std::this_thread::sleep_for(period);
        }
        if (argc > 7 && std::string(argv[7]) == "hold")
            for (;;)
                std::this_thread::sleep_for(std::chrono::seconds(1));
        std::this_thread::sleep_for(std::chrono::milliseconds(300)); // reliable: let the last sample out
        part->delete_contained_entities();
        DomainParticipantFactory::get_instance()->delete_participant(part);
        return 0;
    }
    return 2;
}
