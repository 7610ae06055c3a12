/* A plain Cyclone DDS node written against the C API and the types idlc generates from ROS 2's IDL
 * (bridge/idl), not through orthoflow's code: what a ROS 2 node on another machine sees of the DDS
 * bridge (issue 23). It subscribes to a graph's objects (and points), optionally teaches the
 * first tracked object a label and waits for the acknowledgement, and prints what it got:
 *
 *   plain_subscriber --graph G [--domain N] [--seconds S] [--points] [--teach LABEL]
 *                    [--raw-command KIND LABEL] [--track N] [--objects-min N]
 *
 * Discovery and interface come from CYCLONEDDS_URI (the test sets the bridge's loopback XML).
 * Exit 0 when it saw at least --objects-min object lists (and an ack when teaching). */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dds/dds.h"
#include "orthoflow_msgs/msg/LearningAck.h"
#include "orthoflow_msgs/msg/LearningCommand.h"
#include "orthoflow_msgs/msg/ObjectArray.h"
#include "sensor_msgs/msg/PointCloud2.h"

#define MAX_LAT 100000

static int64_t wall_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_REALTIME, &t);
  return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

static int cmp_i64(const void* a, const void* b) {
  const int64_t x = *(const int64_t*)a, y = *(const int64_t*)b;
  return (x > y) - (x < y);
}

static dds_qos_t* qos(int reliable, int depth) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_SECS(1));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  return q;
}

/* A command written before the bridge's command reader has matched this writer (discovery runs
 * per endpoint, and over a lossy link the objects can match first) is never delivered: volatile
 * samples go to the readers matched when they are written. So the command waits until its writer
 * and the acknowledgement reader have each matched the bridge. */
static int command_matched(dds_entity_t w_cmd, dds_entity_t r_ack) {
  dds_publication_matched_status_t pub;
  dds_subscription_matched_status_t sub;
  return dds_get_publication_matched_status(w_cmd, &pub) == DDS_RETCODE_OK &&
         dds_get_subscription_matched_status(r_ack, &sub) == DDS_RETCODE_OK &&
         pub.current_count > 0 && sub.current_count > 0;
}

int main(int argc, char** argv) {
  const char* graph = "tabletop";
  const char* teach = NULL;
  int raw_kind = -1;
  const char* raw_label = "";
  int domain = 0, points = 0, objects_min = 1;
  int all = 0; /* --all: run the whole --seconds (measurements), printing a line per second */
  long long track = -1; /* --track N: command this track instead of the first one seen */
  double seconds = 10.0;
  for (int i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--graph") && i + 1 < argc) graph = argv[++i];
    else if (!strcmp(argv[i], "--domain") && i + 1 < argc) domain = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--seconds") && i + 1 < argc) seconds = atof(argv[++i]);
    else if (!strcmp(argv[i], "--points")) points = 1;
    else if (!strcmp(argv[i], "--teach") && i + 1 < argc) teach = argv[++i];
    else if (!strcmp(argv[i], "--raw-command") && i + 2 < argc) {
      raw_kind = atoi(argv[++i]);
      raw_label = argv[++i];
    } else if (!strcmp(argv[i], "--objects-min") && i + 1 < argc) objects_min = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--track") && i + 1 < argc) track = atoll(argv[++i]);
    else if (!strcmp(argv[i], "--all")) all = 1;
    else {
      fprintf(stderr, "plain_subscriber: unknown argument %s\n", argv[i]);
      return 2;
    }
  }
  char name[256];
  const dds_entity_t pp = dds_create_participant((dds_domainid_t)domain, NULL, NULL);
  if (pp < 0) {
    fprintf(stderr, "participant: %s\n", dds_strretcode(pp));
    return 1;
  }
  snprintf(name, sizeof name, "rt/orthoflow/%s/objects", graph);
  const dds_entity_t t_obj =
      dds_create_topic(pp, &orthoflow_msgs_msg_dds__ObjectArray__desc, name, NULL, NULL);
  /* Deep enough for what a writer resends after a partition (the bridge's objects depth). */
  dds_qos_t* q = qos(1, 200);
  const dds_entity_t r_obj = dds_create_reader(pp, t_obj, q, NULL);
  dds_delete_qos(q);
  dds_entity_t r_pts = 0;
  if (points) {
    snprintf(name, sizeof name, "rt/orthoflow/%s/points", graph);
    const dds_entity_t t_pts =
        dds_create_topic(pp, &sensor_msgs_msg_dds__PointCloud2__desc, name, NULL, NULL);
    q = qos(0, 1);
    r_pts = dds_create_reader(pp, t_pts, q, NULL);
    dds_delete_qos(q);
  }
  snprintf(name, sizeof name, "rt/orthoflow/%s/learning_commands", graph);
  const dds_entity_t t_cmd =
      dds_create_topic(pp, &orthoflow_msgs_msg_dds__LearningCommand__desc, name, NULL, NULL);
  q = qos(1, 64);
  const dds_entity_t w_cmd = dds_create_writer(pp, t_cmd, q, NULL);
  dds_delete_qos(q);
  snprintf(name, sizeof name, "rt/orthoflow/%s/learning_acks", graph);
  const dds_entity_t t_ack =
      dds_create_topic(pp, &orthoflow_msgs_msg_dds__LearningAck__desc, name, NULL, NULL);
  q = qos(1, 64);
  const dds_entity_t r_ack = dds_create_reader(pp, t_ack, q, NULL);
  dds_delete_qos(q);
  if (r_obj < 0 || w_cmd < 0 || r_ack < 0 || r_pts < 0) {
    fprintf(stderr, "entities: %s\n", dds_strretcode(r_obj < 0 ? r_obj : w_cmd < 0 ? w_cmd : r_ack));
    return 1;
  }

  static int64_t latency[MAX_LAT];
  int lists = 0, clouds = 0, acks = 0, sent = 0, lat_n = 0;
  uint64_t last_frame = 0, out_of_order = 0, gaps = 0, taught_track = 0;
  int64_t next_second = wall_ns() + 1000000000;
  int second = 0;
  const uint64_t client = 0x5eedULL ^ (uint64_t)wall_ns();
  const int64_t end = wall_ns() + (int64_t)(seconds * 1e9);
  int want_command = teach != NULL || raw_kind >= 0;
  /* Acks are volatile: one the bridge writes before its ack writer has matched this reader (under
   * loss, discovery is matched one direction before the other) reaches no one. So, as a client
   * should, the command is sent again, as a new request, when no ack came in 3 s (at most 3 times). */
  int64_t sent_ns = 0;
  int resends = 0;
  uint64_t request = 0;
  while (wall_ns() < end) {
    void* samples[8] = {0};
    dds_sample_info_t infos[8];
    int n = dds_take(r_obj, samples, infos, 8, 8);
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const orthoflow_msgs_msg_dds__ObjectArray_* a = samples[i];
      if (lat_n < MAX_LAT) latency[lat_n++] = wall_ns() - infos[i].source_timestamp;
      if (lists > 0 && a->frame_number <= last_frame) ++out_of_order;
      if (lists > 0 && a->frame_number > last_frame + 1) gaps += a->frame_number - last_frame - 1;
      last_frame = a->frame_number;
      if (lists == 0)
        printf("objects: frame %" PRIu64 " frame_id %s, %u objects, table %s (%s, gravity %s)\n",
               a->frame_number, a->header.frame_id, a->objects._length,
               a->table ? "true" : "false", a->table_reason, a->gravity);
      for (uint32_t k = 0; k < a->objects._length; ++k) {
        const orthoflow_msgs_msg_dds__Object_* o = &a->objects._buffer[k];
        const double qn = sqrt(o->pose.orientation.x * o->pose.orientation.x +
                               o->pose.orientation.y * o->pose.orientation.y +
                               o->pose.orientation.z * o->pose.orientation.z +
                               o->pose.orientation.w * o->pose.orientation.w);
        if (fabs(qn - 1.0) > 1e-6) printf("bad quaternion: track %" PRIu64 "\n", o->track_id);
        if (want_command && !sent && o->track_id != 0 && o->track_id < 0xffffffffULL &&
            command_matched(w_cmd, r_ack)) {
          orthoflow_msgs_msg_dds__LearningCommand_ c;
          memset(&c, 0, sizeof c);
          c.client = client;
          c.request = ++request;
          c.kind = (uint8_t)(raw_kind >= 0 ? raw_kind : 0);
          c.track_id = track >= 0 ? (uint32_t)track : (uint32_t)o->track_id;
          c.label = (char*)(raw_kind >= 0 ? raw_label : teach);
          const dds_return_t rc = dds_write(w_cmd, &c);
          if (rc < 0) fprintf(stderr, "command: %s\n", dds_strretcode(rc));
          else {
            sent = 1;
            sent_ns = wall_ns();
            taught_track = c.track_id;
            printf("command: kind %d track %" PRIu64 " label '%s'\n", c.kind, taught_track, c.label);
          }
        }
      }
      ++lists;
    }
    if (n > 0) dds_return_loan(r_obj, samples, n);
    if (r_pts) {
      void* ps[1] = {0};
      dds_sample_info_t pi[1];
      const int m = dds_take(r_pts, ps, pi, 1, 1);
      if (m > 0 && pi[0].valid_data) {
        const sensor_msgs_msg_dds__PointCloud2_* c = ps[0];
        if (clouds == 0)
          printf("points: %ux%u, %u fields (%s), point_step %u, row_step %u, %u bytes, dense %d\n",
                 c->width, c->height, c->fields._length,
                 c->fields._length > 0 ? c->fields._buffer[0].name : "", c->point_step,
                 c->row_step, c->data._length, (int)c->is_dense);
        ++clouds;
      }
      if (m > 0) dds_return_loan(r_pts, ps, m);
    }
    void* as[4] = {0};
    dds_sample_info_t ai[4];
    const int k = dds_take(r_ack, as, ai, 4, 4);
    for (int i = 0; i < k; ++i) {
      if (!ai[i].valid_data) continue;
      const orthoflow_msgs_msg_dds__LearningAck_* a = as[i];
      if (a->client != client) continue;
      printf("ack: request %" PRIu64 " status %u outcome '%s' problem '%s' track %u label '%s'\n",
             a->request, a->status, a->outcome, a->problem, a->track_id, a->label);
      ++acks;
    }
    if (k > 0) dds_return_loan(r_ack, as, k);
    if (sent && acks == 0 && resends < 3 && wall_ns() - sent_ns > 3000000000LL) {
      sent = 0; /* the next object list with a track sends it again */
      ++resends;
      printf("command: no ack in 3 s, sending again\n");
    }
    if (wall_ns() >= next_second) {
      if (all) printf("second %d: %d object lists, %d clouds, %d acks\n", ++second, lists, clouds, acks);
      fflush(stdout);
      next_second += 1000000000;
    }
    if (!all && lists >= objects_min && (!points || clouds > 0) && (!want_command || acks > 0))
      break;
    dds_sleepfor(DDS_MSECS(2));
  }
  qsort(latency, (size_t)lat_n, sizeof latency[0], cmp_i64);
  printf("received: %d object lists (%" PRIu64 " out of order, %" PRIu64 " missing), %d clouds, %d acks\n",
         lists, out_of_order, gaps, clouds, acks);
  if (lat_n > 0)
    printf("latency: p50 %.3f ms p99 %.3f ms over %d\n", latency[lat_n / 2] / 1e6,
           latency[(lat_n * 99) / 100] / 1e6, lat_n);
  dds_delete(pp);
  return lists >= objects_min && (!points || clouds > 0) && (!want_command || acks > 0) ? 0 : 1;
}
