/* A plain Cyclone DDS node that stops the arm through the DDS bridge (docs/SAFETY.md section 4),
 * written against the C API and the types idlc generates from bridge/idl, not through orthoflow's
 * code: what a ROS 2 node on another machine does. It writes one orthoflow_msgs/ArmStop on
 * rt/orthoflow/arm/stop once the bridge has matched, waits for the ArmStopAck with its reason on
 * rt/orthoflow/arm/stop_ack, and prints it with the round trip it measured:
 *
 *   plain_arm_stop [--domain N] [--seconds S] [--reason TEXT]
 *
 * Exit 0 when an answer came (whatever it says), 1 when none did within --seconds. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dds/dds.h"
#include "orthoflow_msgs/msg/ArmStop.h"
#include "orthoflow_msgs/msg/ArmStopAck.h"

static int64_t mono_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

static dds_qos_t* reliable16(void) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 16);
  return q;
}

int main(int argc, char** argv) {
  int domain = 0;
  double seconds = 20.0;
  const char* reason = "plain DDS node";
  for (int i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--domain") && i + 1 < argc)
      domain = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--seconds") && i + 1 < argc)
      seconds = atof(argv[++i]);
    else if (!strcmp(argv[i], "--reason") && i + 1 < argc)
      reason = argv[++i];
    else {
      fprintf(stderr, "plain_arm_stop: unknown argument %s\n", argv[i]);
      return 2;
    }
  }
  const dds_entity_t pp = dds_create_participant((dds_domainid_t)domain, NULL, NULL);
  if (pp < 0) {
    fprintf(stderr, "participant: %s\n", dds_strretcode(pp));
    return 1;
  }
  const dds_entity_t t_stop = dds_create_topic(pp, &orthoflow_msgs_msg_dds__ArmStop__desc,
                                               "rt/orthoflow/arm/stop", NULL, NULL);
  const dds_entity_t t_ack = dds_create_topic(pp, &orthoflow_msgs_msg_dds__ArmStopAck__desc,
                                              "rt/orthoflow/arm/stop_ack", NULL, NULL);
  dds_qos_t* q = reliable16();
  const dds_entity_t w = dds_create_writer(pp, t_stop, q, NULL);
  const dds_entity_t r = dds_create_reader(pp, t_ack, q, NULL);
  dds_delete_qos(q);
  if (w < 0 || r < 0) {
    fprintf(stderr, "entities: %s\n", dds_strretcode(w < 0 ? w : r));
    return 1;
  }
  const int64_t end = mono_ns() + (int64_t)(seconds * 1e9);
  /* A volatile sample reaches only the readers matched when it is written: wait for the bridge. */
  for (;;) {
    dds_publication_matched_status_t pub;
    dds_subscription_matched_status_t sub;
    if (dds_get_publication_matched_status(w, &pub) == DDS_RETCODE_OK &&
        dds_get_subscription_matched_status(r, &sub) == DDS_RETCODE_OK && pub.current_count > 0 &&
        sub.current_count > 0)
      break;
    if (mono_ns() > end) {
      printf("no bridge matched within %.1f s\n", seconds);
      return 1;
    }
    dds_sleepfor(DDS_MSECS(5));
  }
  orthoflow_msgs_msg_dds__ArmStop_ stop;
  stop.reason = (char*)reason;
  const int64_t sent = mono_ns();
  const dds_return_t rc = dds_write(w, &stop);
  if (rc < 0) {
    fprintf(stderr, "write: %s\n", dds_strretcode(rc));
    return 1;
  }
  while (mono_ns() < end) {
    void* samples[4] = {0};
    dds_sample_info_t infos[4];
    const int n = dds_take(r, samples, infos, 4, 4);
    int done = 0;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const orthoflow_msgs_msg_dds__ArmStopAck_* a = samples[i];
      if (strcmp(a->reason, reason) != 0) continue;
      printf(
          "ack: stopped %d was_moving %d holder_pid %d holder '%s' problem '%s' "
          "request_to_halt_ms %.3f round_trip_ms %.3f\n",
          (int)a->stopped, (int)a->was_moving, (int)a->holder_pid, a->holder, a->problem,
          a->request_to_halt_ms, (double)(mono_ns() - sent) / 1e6);
      done = 1;
    }
    if (n > 0) dds_return_loan(r, samples, n);
    if (done) {
      dds_delete(pp);
      return 0;
    }
    dds_sleepfor(DDS_MSECS(1));
  }
  printf("no answer within %.1f s\n", seconds);
  dds_delete(pp);
  return 1;
}
