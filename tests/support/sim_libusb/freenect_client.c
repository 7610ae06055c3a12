/* A libfreenect program that knows nothing of orthoflow: it opens Kinect 0, streams depth in one
 * mode and writes what libfreenect delivers, so that freenect_check_test.cpp can compare it with
 * the simulator. Linked against libfreenect (which links libusb-1.0); run with LD_LIBRARY_PATH
 * pointing at the sim_libusb shim, it talks to the simulated Kinect.
 *
 * usage: freenect_client 11bit|mm|registered FRAMES OUTDIR
 * (registered: FREENECT_DEPTH_REGISTERED, millimetres re-projected into the RGB image)
 * writes OUTDIR/<mode>-<i>.raw (640 x 480 host-order u16, i from 0), OUTDIR/<mode>-index.txt (one
 * "<i> <timestamp>" line per frame) and OUTDIR/devices.txt ("count <n>" and one "serial <s>" line
 * per device libfreenect lists). Exit status 0 only if FRAMES frames arrived within 20 s.
 *
 * usage: freenect_client 11bit|mm PERIODS -
 * (bench/drivers/kinect/loss_vs_libfreenect.sh) streams every frame libfreenect delivers to stdout as one
 * record each: the callback's 60 MHz timestamp (u32, host order), then 640 x 480 host-order u16.
 * Stops after the first frame at least PERIODS frame periods (2,000,000 ticks each) after the
 * first delivered frame, so a frame lost before that is never waited for; the messages go to
 * stderr. Exit status 0 only if that frame arrived before the deadline (20 s + 3 x PERIODS / 30).
 */
#include <libfreenect.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* libfreenect's fakenect replay library has no device attributes: resolved weakly, so the same
 * program also runs under the `fakenect` wrapper (check_fakenect_interop.sh), listing no serials.
 */
#pragma weak freenect_list_device_attributes
#pragma weak freenect_free_device_attributes

static const char* g_outdir = NULL;
static const char* g_mode_name = NULL;
static int g_wanted = 0;
static int g_frames = 0;
static int g_failed = 0;
static FILE* g_index = NULL;
static int g_stream = 0; /* OUTDIR "-": records to stdout until PERIODS periods are covered */
static int g_have_first = 0;
static uint32_t g_first_timestamp = 0;
static int g_span_reached = 0;

static void on_depth_stream(void* data, uint32_t timestamp) {
  if (g_span_reached || g_failed) return;
  if (!g_have_first) {
    g_have_first = 1;
    g_first_timestamp = timestamp;
  }
  if (fwrite(&timestamp, sizeof timestamp, 1, stdout) != 1 ||
      fwrite(data, sizeof(uint16_t), 640 * 480, stdout) != 640 * 480) {
    fprintf(stderr, "freenect_client: cannot write a record to stdout\n");
    g_failed = 1;
    return;
  }
  ++g_frames;
  /* Unsigned arithmetic: the 32-bit device clock wraps every 71.6 s. */
  if ((uint32_t)(timestamp - g_first_timestamp) / 2000000U >= (uint32_t)g_wanted)
    g_span_reached = 1;
}

static void on_depth(freenect_device* dev, void* data, uint32_t timestamp) {
  (void)dev;
  if (g_stream) {
    on_depth_stream(data, timestamp);
    return;
  }
  if (g_frames >= g_wanted || g_failed) return;
  char path[4096];
  snprintf(path, sizeof path, "%s/%s-%d.raw", g_outdir, g_mode_name, g_frames);
  FILE* f = fopen(path, "wb");
  if (f == NULL || fwrite(data, sizeof(uint16_t), 640 * 480, f) != 640 * 480) {
    fprintf(stderr, "freenect_client: cannot write %s\n", path);
    g_failed = 1;
  }
  if (f != NULL) fclose(f);
  fprintf(g_index, "%d %u\n", g_frames, timestamp);
  ++g_frames;
}

static double seconds_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int list_devices(freenect_context* ctx) {
  char path[4096];
  snprintf(path, sizeof path, "%s/devices.txt", g_outdir);
  FILE* f = fopen(path, "w");
  if (f == NULL) return -1;
  const int count = freenect_num_devices(ctx);
  fprintf(f, "count %d\n", count);
  struct freenect_device_attributes* list = NULL;
  if (freenect_list_device_attributes != NULL && freenect_list_device_attributes(ctx, &list) >= 0) {
    for (struct freenect_device_attributes* a = list; a != NULL; a = a->next)
      fprintf(f, "serial %s\n", a->camera_serial);
    freenect_free_device_attributes(list);
  }
  fclose(f);
  return count;
}

int main(int argc, char** argv) {
  if (argc != 4 || (strcmp(argv[1], "11bit") != 0 && strcmp(argv[1], "mm") != 0 &&
                    strcmp(argv[1], "registered") != 0)) {
    fprintf(stderr, "usage: freenect_client 11bit|mm|registered FRAMES OUTDIR\n");
    return 2;
  }
  g_mode_name = argv[1];
  g_wanted = atoi(argv[2]);
  g_outdir = argv[3];
  g_stream = strcmp(g_outdir, "-") == 0;
  const freenect_depth_format format = strcmp(argv[1], "mm") == 0 ? FREENECT_DEPTH_MM
                                       : strcmp(argv[1], "registered") == 0
                                           ? FREENECT_DEPTH_REGISTERED
                                           : FREENECT_DEPTH_11BIT;

  char path[4096];
  snprintf(path, sizeof path, "%s/%s-index.txt", g_outdir, g_mode_name);
  g_index = g_stream ? NULL : fopen(path, "w");
  if (!g_stream && g_index == NULL) {
    fprintf(stderr, "freenect_client: cannot write %s\n", path);
    return 1;
  }

  freenect_context* ctx = NULL;
  if (freenect_init(&ctx, NULL) < 0) {
    fprintf(stderr, "freenect_client: freenect_init failed\n");
    return 1;
  }
  freenect_set_log_level(ctx, FREENECT_LOG_NOTICE);
  freenect_select_subdevices(
      ctx, (freenect_device_flags)(FREENECT_DEVICE_MOTOR | FREENECT_DEVICE_CAMERA));
  if ((g_stream ? freenect_num_devices(ctx) : list_devices(ctx)) < 1) {
    fprintf(stderr, "freenect_client: no Kinect found\n");
    freenect_shutdown(ctx);
    return 1;
  }
  freenect_device* dev = NULL;
  if (freenect_open_device(ctx, &dev, 0) < 0) {
    fprintf(stderr, "freenect_client: cannot open device 0\n");
    freenect_shutdown(ctx);
    return 1;
  }
  const freenect_frame_mode mode = freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, format);
  if (!mode.is_valid || mode.width != 640 || mode.height != 480 ||
      freenect_set_depth_mode(dev, mode) < 0) {
    fprintf(stderr, "freenect_client: cannot select the %s depth mode\n", g_mode_name);
    return 1;
  }
  freenect_set_depth_callback(dev, on_depth);
  if (freenect_start_depth(dev) < 0) {
    fprintf(stderr, "freenect_client: cannot start depth\n");
    return 1;
  }
  const double deadline = seconds_now() + 20.0 + (g_stream ? 3.0 * g_wanted / 30.0 : 0.0);
  while ((g_stream ? !g_span_reached : g_frames < g_wanted) && !g_failed &&
         seconds_now() < deadline) {
    if (freenect_process_events(ctx) < 0) {
      fprintf(stderr, "freenect_client: freenect_process_events failed\n");
      g_failed = 1;
    }
  }
  freenect_stop_depth(dev);
  freenect_close_device(dev);
  freenect_shutdown(ctx);
  if (g_stream) {
    fflush(stdout);
    fprintf(stderr, "freenect_client: %d %s frames streamed over %s %d periods\n", g_frames,
            g_mode_name, g_span_reached ? "all" : "fewer than", g_wanted);
    return g_span_reached && !g_failed ? 0 : 1;
  }
  fclose(g_index);
  printf("freenect_client: %d %s frames\n", g_frames, g_mode_name);
  return g_frames == g_wanted && !g_failed ? 0 : 1;
}
