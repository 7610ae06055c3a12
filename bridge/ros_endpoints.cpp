#include "bridge/ros_endpoints.hpp"

#include <array>

#include <dds/dds.h>

namespace orthoflow::bridge {
namespace {

dds_qos_t* make_qos(const TopicQos& q) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, q.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, static_cast<std::int32_t>(q.depth));
  dds_qset_durability(qos,
                      q.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  return qos;
}

struct QosDeleter {
  void operator()(dds_qos_t* q) const noexcept { dds_delete_qos(q); }
};
using QosPtr = std::unique_ptr<dds_qos_t, QosDeleter>;

}  // namespace

std::string dds_error(std::int32_t rc) { return std::string(dds_strretcode(rc)); }

Result<std::unique_ptr<RosEndpoints>, std::string> RosEndpoints::open(const BridgeConfig& config) {
  if (auto ok = check_bridge_config(config); !ok) return err(ok.error());
  std::unique_ptr<RosEndpoints> e(new RosEndpoints());
  e->topics_ = bridge_topics(config);
  e->domain_ = config.domain;
  e->frames_ = config.frames;
  e->scratch_.camera_frame.fill('\0');
  config.camera_frame.copy(e->scratch_.camera_frame.data(), e->scratch_.camera_frame.size() - 1);
  const std::string xml = cyclone_xml(config);
  const dds_entity_t domain = dds_create_domain(config.domain, xml.c_str());
  if (domain < 0)  // PRECONDITION_NOT_MET: this process has that domain already (configured so)
    return err("DDS domain " + std::to_string(config.domain) + " on " + config.interface + ": " +
               dds_error(domain));
  e->domain_entity_ = domain;
  e->participant_ = dds_create_participant(config.domain, nullptr, nullptr);
  if (e->participant_ < 0) return err("DDS participant: " + dds_error(e->participant_));
  const auto topic = [&](const dds_topic_descriptor_t* d, const std::string& name,
                         std::int32_t& out) -> Result<void, std::string> {
    out = dds_create_topic(e->participant_, d, name.c_str(), nullptr, nullptr);
    if (out < 0) return err("DDS topic " + name + ": " + dds_error(out));
    return {};
  };
  if (auto ok =
          topic(&orthoflow_msgs_msg_dds__ObjectArray__desc, e->topics_.objects, e->objects_topic_);
      !ok)
    return err(ok.error());
  if (auto ok = topic(&orthoflow_msgs_msg_dds__LearningCommand__desc, e->topics_.learning_commands,
                      e->commands_topic_);
      !ok)
    return err(ok.error());
  if (auto ok = topic(&orthoflow_msgs_msg_dds__LearningAck__desc, e->topics_.learning_acks,
                      e->acks_topic_);
      !ok)
    return err(ok.error());
  const auto writer = [&](std::int32_t topic_entity, const TopicQos& q, const std::string& name,
                          std::int32_t& out) -> Result<void, std::string> {
    const QosPtr qos(make_qos(q));
    out = dds_create_writer(e->participant_, topic_entity, qos.get(), nullptr);
    if (out < 0) return err("DDS writer " + name + ": " + dds_error(out));
    return {};
  };
  if (auto ok =
          writer(e->objects_topic_, config.objects_qos, e->topics_.objects, e->objects_writer_);
      !ok)
    return err(ok.error());
  if (auto ok = writer(e->acks_topic_, config.acks_qos, e->topics_.learning_acks, e->acks_writer_);
      !ok)
    return err(ok.error());
  if (config.frames) {
    if (auto ok =
            topic(&sensor_msgs_msg_dds__PointCloud2__desc, e->topics_.points, e->points_topic_);
        !ok)
      return err(ok.error());
    if (auto ok = writer(e->points_topic_, config.frames_qos, e->topics_.points, e->points_writer_);
        !ok)
      return err(ok.error());
  }
  // The arm's stop: reliable, every request kept until taken (a stop is never dropped for depth).
  const TopicQos stop_qos{true, 16, false};
  if (auto ok =
          topic(&orthoflow_msgs_msg_dds__ArmStop__desc, e->topics_.arm_stop, e->arm_stop_topic_);
      !ok)
    return err(ok.error());
  if (auto ok = topic(&orthoflow_msgs_msg_dds__ArmStopAck__desc, e->topics_.arm_stop_acks,
                      e->arm_stop_ack_topic_);
      !ok)
    return err(ok.error());
  if (auto ok = writer(e->arm_stop_ack_topic_, stop_qos, e->topics_.arm_stop_acks,
                       e->arm_stop_ack_writer_);
      !ok)
    return err(ok.error());
  if (is_loopback(config.interface) || config.accept_network_commands) {
    const QosPtr stop(make_qos(stop_qos));
    e->arm_stop_reader_ =
        dds_create_reader(e->participant_, e->arm_stop_topic_, stop.get(), nullptr);
    if (e->arm_stop_reader_ < 0)
      return err("DDS reader " + e->topics_.arm_stop + ": " + dds_error(e->arm_stop_reader_));
    const QosPtr qos(make_qos(config.commands_qos));
    e->commands_reader_ =
        dds_create_reader(e->participant_, e->commands_topic_, qos.get(), nullptr);
    if (e->commands_reader_ < 0)
      return err("DDS reader " + e->topics_.learning_commands + ": " +
                 dds_error(e->commands_reader_));
  }
  return e;
}

RosEndpoints::~RosEndpoints() {
  // The domain and all in it: a later open() configures it anew.
  if (domain_entity_ > 0) (void)dds_delete(domain_entity_);
}

Result<std::size_t, std::string> RosEndpoints::write_objects(
    const engine::ObjectListPayload& list) {
  RosObjectArray msg{};
  const std::size_t n = to_ros(list, clock_, scratch_, msg);
  const dds_return_t rc = dds_write(objects_writer_, &msg);
  if (rc < 0) return err("objects: " + dds_error(rc));
  return n * sizeof(RosObject);
}

Result<std::size_t, std::string> RosEndpoints::write_frame(const engine::FrameView& frame) {
  if (!frames_) return err(std::string("frames are not bridged (frames: false)"));
  RosPointCloud2 msg{};
  const std::size_t bytes = to_ros(frame, clock_, scratch_, msg);
  const dds_return_t rc = dds_write(points_writer_, &msg);
  if (rc < 0) return err("points: " + dds_error(rc));
  return bytes;
}

std::size_t RosEndpoints::take_commands(
    std::size_t max, const std::function<void(const RosLearningCommand&)>& on_command) {
  if (commands_reader_ <= 0) return 0;
  constexpr std::size_t BATCH = 16;
  std::size_t taken = 0;
  while (taken < max) {
    std::array<void*, BATCH> samples{};
    std::array<dds_sample_info_t, BATCH> infos{};
    const dds_return_t n = dds_take(commands_reader_, samples.data(), infos.data(), BATCH, BATCH);
    if (n <= 0) break;
    for (dds_return_t i = 0; i < n; ++i) {
      if (infos[static_cast<std::size_t>(i)].valid_data)
        on_command(*static_cast<const RosLearningCommand*>(samples[static_cast<std::size_t>(i)]));
    }
    (void)dds_return_loan(commands_reader_, samples.data(), n);
    taken += static_cast<std::size_t>(n);
    if (static_cast<std::size_t>(n) < BATCH) break;
  }
  return taken;
}

std::size_t RosEndpoints::take_arm_stops(
    std::size_t max, const std::function<void(std::string_view reason)>& on_stop) {
  if (arm_stop_reader_ <= 0) return 0;
  std::size_t taken = 0;
  while (taken < max) {
    std::array<void*, 1> sample{};
    std::array<dds_sample_info_t, 1> info{};
    const dds_return_t n = dds_take(arm_stop_reader_, sample.data(), info.data(), 1, 1);
    if (n <= 0) break;
    if (info[0].valid_data) {
      const auto* stop = static_cast<const RosArmStop*>(sample[0]);
      on_stop(stop->reason != nullptr ? std::string_view(stop->reason) : std::string_view());
    }
    (void)dds_return_loan(arm_stop_reader_, sample.data(), n);
    ++taken;
  }
  return taken;
}

Result<void, std::string> RosEndpoints::write_arm_stop_ack(const RosArmStopAck& ack) {
  const dds_return_t rc = dds_write(arm_stop_ack_writer_, &ack);
  if (rc < 0) return err("arm stop acks: " + dds_error(rc));
  return {};
}

Result<void, std::string> RosEndpoints::write_ack(const graphs::RemoteAck& ack,
                                                  const AckRoute& route, std::string_view problem) {
  RosLearningAck msg{};
  to_ros(ack, route.client, route.request, problem, ack_scratch_, msg);
  const dds_return_t rc = dds_write(acks_writer_, &msg);
  if (rc < 0) return err("acks: " + dds_error(rc));
  return {};
}

DdsStatus RosEndpoints::status() const {
  DdsStatus s;
  dds_publication_matched_status_t pm{};
  if (dds_get_publication_matched_status(objects_writer_, &pm) == 0)
    s.objects_readers = pm.current_count;
  if (points_writer_ > 0 && dds_get_publication_matched_status(points_writer_, &pm) == 0)
    s.points_readers = pm.current_count;
  dds_inconsistent_topic_status_t it{};
  for (const std::int32_t t : {objects_topic_, points_topic_, commands_topic_, acks_topic_}) {
    if (t > 0 && dds_get_inconsistent_topic_status(t, &it) == 0)
      s.inconsistent_topics += it.total_count;
  }
  if (commands_reader_ > 0) {
    dds_subscription_matched_status_t sm{};
    if (dds_get_subscription_matched_status(commands_reader_, &sm) == 0)
      s.command_writers = sm.current_count;
    dds_sample_lost_status_t lost{};
    if (dds_get_sample_lost_status(commands_reader_, &lost) == 0)
      s.commands_lost = lost.total_count;
    dds_sample_rejected_status_t rej{};
    if (dds_get_sample_rejected_status(commands_reader_, &rej) == 0)
      s.commands_rejected = rej.total_count;
  }
  return s;
}

}  // namespace orthoflow::bridge
