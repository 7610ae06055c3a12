// Fuzzes what a DDS peer can send the bridge on its learning-commands topic (bridge/, issue 23):
// the bytes of a sample as they come off the network (CDR, with its 4-byte encoding header) are
// deserialised by Cyclone DDS with the generated orthoflow_msgs LearningCommand type, then go
// through bridge::from_ros, the bridge's own check. No input may crash, hang, leak or hit UB; a
// command the bridge accepts must pass graphs::decode_command (the graph's check) and keep the
// kind, track and label it came with.
#include <cstdint>
#include <cstring>
#include <string_view>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include "bridge/ros_messages.hpp"
#include "core/label_text.hpp"

namespace b = orthoflow::bridge;

namespace {

const ddsi_sertype* g_type = nullptr;

// A participant on a private loopback domain; the topic's sertype from one sample's serialised
// form (Cyclone 0.10.2 has no public getter).
void make_type() {
  // The bridge's loopback configuration (bridge::cyclone_xml of the defaults).
  constexpr const char* LOOPBACK =
      "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/>"
      "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
      "<ParticipantIndex>auto</ParticipantIndex><Peers><Peer Address=\"127.0.0.1\"/></Peers>"
      "</Discovery></Domain></CycloneDDS>";
  const dds_entity_t domain = dds_create_domain(230, LOOPBACK);
  const dds_entity_t pp = dds_create_participant(230, nullptr, nullptr);
  const dds_entity_t topic = dds_create_topic(pp, &orthoflow_msgs_msg_dds__LearningCommand__desc,
                                              "rt/fuzz/learning_commands", nullptr, nullptr);
  const dds_entity_t writer = dds_create_writer(pp, topic, nullptr, nullptr);
  const dds_entity_t reader = dds_create_reader(pp, topic, nullptr, nullptr);
  if (domain < 0 || pp < 0 || topic < 0 || writer < 0 || reader < 0) __builtin_trap();
  b::RosLearningCommand empty{};
  empty.label = const_cast<char*>("");
  if (dds_write(writer, &empty) != 0) __builtin_trap();
  ddsi_serdata* sd = nullptr;
  dds_sample_info_t info{};
  if (dds_takecdr(reader, &sd, 1, &info, DDS_ANY_STATE) != 1) __builtin_trap();
  g_type = sd->type;  // the topic lives as long as the process
  ddsi_serdata_unref(sd);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (g_type == nullptr) make_type();
  ddsrt_iovec_t iov{};
  iov.iov_base = const_cast<std::uint8_t*>(data);
  iov.iov_len = static_cast<ddsrt_iov_len_t>(size);
  ddsi_serdata* sd = ddsi_serdata_from_ser_iov(g_type, SDK_DATA, 1, &iov, size);
  if (sd == nullptr) return 0;  // Cyclone refused it: nothing reaches the bridge
  b::RosLearningCommand c{};
  if (ddsi_serdata_to_sample(sd, &c, nullptr, nullptr)) {
    auto payload = b::from_ros(c, 7, 1);
    if (payload) {
      auto decoded = orthoflow::graphs::decode_command(std::as_bytes(
          std::span<const orthoflow::graphs::LearningCommandPayload, 1>(&*payload, 1)));
      if (!decoded) __builtin_trap();  // the bridge let through what the graph refuses
      if (static_cast<std::uint8_t>(decoded->command.kind) != c.kind) __builtin_trap();
      if (decoded->command.track_id != c.track_id || c.client == 0) __builtin_trap();
      const bool labelled = c.kind <= 2;
      if (labelled &&
          (c.label == nullptr || decoded->command.label.view() != std::string_view(c.label)))
        __builtin_trap();
    } else if (payload.error().message.empty()) {
      __builtin_trap();
    }
    dds_sample_free(&c, &orthoflow_msgs_msg_dds__LearningCommand__desc, DDS_FREE_CONTENTS);
  }
  ddsi_serdata_unref(sd);
  return 0;
}
