// A libusb-1.0 compatible shim (SONAME libusb-1.0.so.0) over simulated Kinects
// (simulation/devices/sim_kinect_device.hpp) and Kinova JACO arms
// (simulation/devices/sim_jaco_arm.hpp), so that unmodified libusb programs (libfreenect,
// orthoflow's LibusbTransport) run against the simulators when started with LD_LIBRARY_PATH=<this
// lib's dir>. Test support only: README.md beside this file documents the behaviour and the
// environment.
//
// Structure: one process-wide World (the simulated bus: devices, open handles, iso queues and the
// simulated clock), created at the first libusb_init and destroyed at the last libusb_exit, and
// guarded by one mutex that is never held while a transfer callback runs.
#include <libusb-1.0/libusb.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <initializer_list>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "simulation/devices/sim_jaco_arm.hpp"
#include "simulation/devices/sim_kinect_device.hpp"
#include "tests/support/sim_libusb/sim_jaco_env.hpp"
#include "tests/support/sim_libusb/sim_kinect_env.hpp"

using orthoflow::simulation::KinectFunction;
using orthoflow::simulation::KinectModel;
using orthoflow::simulation::SimControlOutcome;
using orthoflow::simulation::SimJacoArm;
using orthoflow::simulation::SimJacoConfig;
using orthoflow::simulation::SimKinectConfig;
using orthoflow::simulation::SimKinectDevice;
using orthoflow::simulation::USB_MICROFRAME_NS;
using SteadyTime = std::chrono::steady_clock::time_point;

namespace {

constexpr std::int64_t NEVER = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t CONTROL_LATENCY_NS = 50'000;       // as SimUsbTransport
constexpr std::int64_t INFINITE_WAIT_NS = 5'000'000'000;  // a stall with timeout 0 ends here
constexpr std::int64_t MAX_LAG_NS = 100'000'000;     // realtime: catch up at most this much at once
constexpr std::int64_t JACO_LATENCY_NS = 1'000'000;  // per transfer, as SimJacoTransport
constexpr std::uint16_t HUB_VENDOR = 0x0409;         // NEC, the Kinect's internal hub chip
constexpr std::uint16_t HUB_PRODUCT = 0x005A;
constexpr std::uint16_t ROOT_HUB_VENDOR = 0x1D6B;  // Linux Foundation
constexpr std::uint16_t ROOT_HUB_PRODUCT = 0x0002;

enum class Kind : std::uint8_t { ROOT_HUB, HUB, FUNCTION, JACO };

struct EndpointSpec {
  std::uint8_t address = 0;
  std::uint8_t attributes = 0;  // LIBUSB_TRANSFER_TYPE_*
  std::uint16_t max_packet = 0;
  std::uint8_t interval = 0;
};
struct AltSpec {
  std::uint8_t endpoints = 0;
  std::array<EndpointSpec, 4> ep{};
};
struct InterfaceSpec {
  std::uint8_t interface_class = 0xFF;
  std::uint8_t alts = 1;
  std::array<AltSpec, 2> alt{};
};

// Per Kinect: state the host side owns (claims, kernel driver).
struct KinectSlot {
  std::unique_ptr<SimKinectDevice> device;
  bool gspca_bound = true;  // the camera's kernel driver, bound at plug-in
  std::array<libusb_device_handle*, 3> claimed_by{};  // interface 0, per function
};

// Per JACO arm (sim_jaco_env.hpp): the arm and the claim of its interface 0.
struct JacoSlot {
  std::unique_ptr<SimJacoArm> arm;
  libusb_device_handle* claimed_by = nullptr;
};

}  // namespace

struct libusb_context {
  bool is_default = false;
};

struct libusb_device {
  Kind kind = Kind::FUNCTION;
  std::size_t kinect = 0;
  KinectFunction function = KinectFunction::CAMERA;
  std::size_t jaco = 0;  // Kind::JACO: its index in World::jacos
  std::uint8_t bus = 0;
  std::uint8_t address = 0;
  std::array<std::uint8_t, 7> ports{};
  std::uint8_t depth = 0;
  libusb_device* parent = nullptr;
  std::atomic<int> refs{0};
  libusb_device_descriptor descriptor{};
  std::array<std::string, 4> strings{};  // index 1..3: manufacturer, product, serial
  InterfaceSpec interface {};
  std::uint8_t config_attributes = 0x80;
  std::uint8_t max_power = 250;  // x 2 mA
};

struct libusb_device_handle {
  libusb_device* device = nullptr;
  bool claimed = false;
  bool detached = false;
  std::uint8_t alt = 0;
};

namespace {

struct TransferState {
  bool in_flight = false;
  bool cancelled = false;
  std::size_t queue = 0;
  std::int64_t first_mf = 0;
  int filled = 0;
  std::size_t offset = 0;  // buffer offset of packet `filled`
};
constexpr std::size_t STATE_BYTES =
    (sizeof(TransferState) + alignof(std::max_align_t) - 1) & ~(alignof(std::max_align_t) - 1);

TransferState& state_of(libusb_transfer* t) noexcept {
  return *reinterpret_cast<TransferState*>(reinterpret_cast<char*>(t) - STATE_BYTES);
}

// The iso transfers queued on one camera endpoint, in bus order.
struct EndpointQueue {
  std::size_t kinect = 0;
  std::uint8_t endpoint = 0;
  std::deque<libusb_transfer*> pending;
  std::int64_t next_free_mf = 0;
};

struct World {
  std::vector<KinectSlot> kinects;
  std::vector<JacoSlot> jacos;
  std::vector<std::unique_ptr<libusb_device>> devices;  // stable addresses
  std::vector<EndpointQueue> queues;                    // 2 per Kinect: 0x81, 0x82
  std::vector<libusb_device_handle*> handles;
  std::vector<libusb_transfer*> cancelled;  // complete CANCELLED at the next event handling
  std::array<std::byte, orthoflow::simulation::KINECT_ISO_MAX_PACKET_BYTES> scratch{};
  std::int64_t now_ns = 0;
  bool realtime = true;
  bool trace = false;
  std::int64_t anchor_sim_ns = 0;
  SteadyTime anchor_wall{};
  int contexts = 0;
};

std::mutex g_mutex;
std::condition_variable g_cv;
World* g_world = nullptr;  // guarded by g_mutex
libusb_context g_default_context{true};
int g_default_refs = 0;

void trace(const World& w, const char* format, ...) {
  if (!w.trace) return;
  std::va_list args;
  va_start(args, format);
  std::fprintf(stderr, "sim_libusb [%10.6f s] ", static_cast<double>(w.now_ns) * 1e-9);
  std::vfprintf(stderr, format, args);
  std::fputc('\n', stderr);
  va_end(args);
}

// ----------------------------------------------------------------------------------------------
// The bus: devices and descriptors.

InterfaceSpec interface_of(const libusb_device& d, KinectModel model) {
  InterfaceSpec spec;
  const EndpointSpec video{0x81, LIBUSB_TRANSFER_TYPE_ISOCHRONOUS, 0x0BC0, 1};
  const EndpointSpec depth{0x82, LIBUSB_TRANSFER_TYPE_ISOCHRONOUS, 0x0BC0, 1};
  if (d.kind != Kind::FUNCTION) {
    spec.interface_class = LIBUSB_CLASS_HUB;
    spec.alt[0] = {1, {EndpointSpec{0x81, LIBUSB_TRANSFER_TYPE_INTERRUPT, 1, 12}}};
    return spec;
  }
  switch (d.function) {
    case KinectFunction::CAMERA:
      if (model == KinectModel::K4W) {  // invented: the streaming endpoints live in alt 1
        spec.alts = 2;
        spec.alt[1] = {2, {video, depth}};
      } else {
        spec.alt[0] = {2, {video, depth}};
      }
      break;
    case KinectFunction::MOTOR:
      break;                     // control transfers only
    case KinectFunction::AUDIO:  // the bootloader's single interface (KINECT_V1.md 1)
      spec.alt[0] = {4,
                     {EndpointSpec{0x81, LIBUSB_TRANSFER_TYPE_BULK, 512, 0},
                      EndpointSpec{0x01, LIBUSB_TRANSFER_TYPE_BULK, 512, 0},
                      EndpointSpec{0x82, LIBUSB_TRANSFER_TYPE_ISOCHRONOUS, 524, 5},
                      EndpointSpec{0x02, LIBUSB_TRANSFER_TYPE_ISOCHRONOUS, 72, 5}}};
      break;
  }
  return spec;
}

libusb_device* add_device(World& w, Kind kind, std::uint8_t bus, std::uint8_t address,
                          std::uint16_t vendor, std::uint16_t product, std::uint16_t bcd,
                          std::string product_name, std::string serial) {
  auto d = std::make_unique<libusb_device>();
  d->kind = kind;
  d->bus = bus;
  d->address = address;
  libusb_device_descriptor& desc = d->descriptor;
  desc.bLength = LIBUSB_DT_DEVICE_SIZE;
  desc.bDescriptorType = LIBUSB_DT_DEVICE;
  desc.bcdUSB = 0x0200;
  const bool hub = kind == Kind::ROOT_HUB || kind == Kind::HUB;
  desc.bDeviceClass = hub ? LIBUSB_CLASS_HUB : 0;
  desc.bMaxPacketSize0 = 64;
  desc.idVendor = vendor;
  desc.idProduct = product;
  desc.bcdDevice = bcd;
  desc.iManufacturer = 1;
  desc.iProduct = 2;
  desc.iSerialNumber = serial.empty() ? 0 : 3;
  desc.bNumConfigurations = 1;
  d->strings[1] = hub ? "orthoflow sim_libusb" : kind == Kind::JACO ? "Kinova inc." : "Microsoft";
  d->strings[2] = std::move(product_name);
  d->strings[3] = std::move(serial);
  w.devices.push_back(std::move(d));
  return w.devices.back().get();
}

// A JACO (JACO.md 1-2, as SimJacoTransport): full speed, self-powered [I], one vendor interface
// with interrupt OUT 0x02 and IN 0x82 of 64 bytes, polled every frame; strings "Kinova inc." and
// "Kinova Robotic Platform" [I: JACO.md has it truncated], the USB serial only if the config has
// one.
void add_jaco(World& w, std::uint8_t address, libusb_device* root, SimJacoConfig config) {
  namespace jaco = orthoflow::drivers::jaco;
  const std::string usb_serial = config.usb_serial;
  libusb_device* d = add_device(w, Kind::JACO, config.bus, address, jaco::VENDOR_KINOVA,
                                jaco::PID_JACO, 0x0100, "Kinova Robotic Platform", usb_serial);
  d->jaco = w.jacos.size();
  d->parent = root;
  d->ports[0] = config.port;
  d->depth = 1;
  d->interface.alt[0] = {2,
                         {EndpointSpec{jaco::EP_OUT, LIBUSB_TRANSFER_TYPE_INTERRUPT, 64, 1},
                          EndpointSpec{jaco::EP_IN, LIBUSB_TRANSFER_TYPE_INTERRUPT, 64, 1}}};
  d->config_attributes = 0xC0;
  d->max_power = 0;
  w.jacos.push_back({std::make_unique<SimJacoArm>(std::move(config), w.now_ns), nullptr});
}

void build_bus(World& w, std::vector<SimKinectConfig> configs, std::vector<SimJacoConfig> jacos) {
  std::array<std::uint8_t, 256> next_address{};
  next_address.fill(2);
  std::array<libusb_device*, 256> root{};
  std::vector<std::uint8_t> buses;
  for (const SimKinectConfig& c : configs) buses.push_back(c.bus);
  for (const SimJacoConfig& c : jacos) buses.push_back(c.bus);
  for (const std::uint8_t bus : buses) {
    if (root[bus] != nullptr) continue;
    root[bus] = add_device(w, Kind::ROOT_HUB, bus, 1, ROOT_HUB_VENDOR, ROOT_HUB_PRODUCT, 0x0606,
                           "EHCI Host Controller", "0000:00:1d.0");
    root[bus]->interface = interface_of(*root[bus], KinectModel::K1414);
  }
  for (std::size_t k = 0; k < configs.size(); ++k) {
    KinectSlot slot;
    slot.device = std::make_unique<SimKinectDevice>(std::move(configs[k]));
    SimKinectDevice& sim = *slot.device;
    const SimKinectConfig& c = sim.config();
    std::uint8_t& next = next_address[c.bus];
    sim.set_first_address(static_cast<std::uint8_t>(next + 1));
    libusb_device* hub =
        add_device(w, Kind::HUB, c.bus, next, HUB_VENDOR, HUB_PRODUCT, 0x0100, "USB2.0 Hub", "");
    next = static_cast<std::uint8_t>(next + 4);
    hub->kinect = k;
    hub->parent = root[c.bus];
    std::copy(c.hub_ports.begin(), c.hub_ports.end(), hub->ports.begin());
    hub->depth = static_cast<std::uint8_t>(c.hub_ports.size());
    hub->interface = interface_of(*hub, c.model);
    hub->config_attributes = 0xE0;
    for (const KinectFunction f :
         {KinectFunction::CAMERA, KinectFunction::MOTOR, KinectFunction::AUDIO}) {
      if (!sim.has_function(f)) continue;
      const orthoflow::drivers::UsbDeviceInfo info = sim.info(f);
      const char* name = f == KinectFunction::CAMERA  ? "Xbox NUI Camera"
                         : f == KinectFunction::MOTOR ? "Xbox NUI Motor"
                                                      : "Xbox NUI Audio";
      libusb_device* d =
          add_device(w, Kind::FUNCTION, info.bus, info.address, info.vendor, info.product,
                     info.bcd_device, name, std::string(info.serial.view()));
      d->kinect = k;
      d->function = f;
      d->parent = hub;
      d->ports = info.port_path;
      d->depth = info.port_depth;
      d->interface = interface_of(*d, c.model);
      d->config_attributes = f == KinectFunction::CAMERA ? 0xC0 : 0x80;
    }
    w.kinects.push_back(std::move(slot));
    w.queues.push_back({k, orthoflow::simulation::KINECT_VIDEO_ENDPOINT, {}, 0});
    w.queues.push_back({k, orthoflow::simulation::KINECT_DEPTH_ENDPOINT, {}, 0});
  }
  for (SimJacoConfig& c : jacos) {  // after the Kinects: the next free address of its bus
    const std::uint8_t bus = c.bus;
    add_jaco(w, next_address[bus]++, root[bus], std::move(c));
  }
}

// The configuration descriptor in libusb's parsed form, one allocation freed by
// libusb_free_config_descriptor.
struct ConfigBlock {
  libusb_config_descriptor config;  // first: the pointer handed out is this block's
  libusb_interface interface;
  std::array<libusb_interface_descriptor, 2> alts;
  std::array<std::array<libusb_endpoint_descriptor, 4>, 2> endpoints;
};

std::uint16_t total_length(const InterfaceSpec& spec) noexcept {
  int n = LIBUSB_DT_CONFIG_SIZE;
  for (std::uint8_t a = 0; a < spec.alts; ++a)
    n += LIBUSB_DT_INTERFACE_SIZE + spec.alt[a].endpoints * LIBUSB_DT_ENDPOINT_SIZE;
  return static_cast<std::uint16_t>(n);
}

libusb_config_descriptor* make_config(const libusb_device& d) {
  auto* block = new ConfigBlock{};
  const InterfaceSpec& spec = d.interface;
  libusb_config_descriptor& c = block->config;
  c.bLength = LIBUSB_DT_CONFIG_SIZE;
  c.bDescriptorType = LIBUSB_DT_CONFIG;
  c.wTotalLength = total_length(spec);
  c.bNumInterfaces = 1;
  c.bConfigurationValue = 1;
  c.bmAttributes = d.config_attributes;
  c.MaxPower = d.max_power;
  c.interface = &block->interface;
  block->interface.altsetting = block->alts.data();
  block->interface.num_altsetting = spec.alts;
  for (std::uint8_t a = 0; a < spec.alts; ++a) {
    libusb_interface_descriptor& i = block->alts[a];
    i.bLength = LIBUSB_DT_INTERFACE_SIZE;
    i.bDescriptorType = LIBUSB_DT_INTERFACE;
    i.bInterfaceNumber = 0;
    i.bAlternateSetting = a;
    i.bNumEndpoints = spec.alt[a].endpoints;
    i.bInterfaceClass = spec.interface_class;
    i.bInterfaceSubClass = spec.interface_class == LIBUSB_CLASS_HUB ? 0 : 0xFF;
    i.bInterfaceProtocol = spec.interface_class == LIBUSB_CLASS_HUB ? 0 : 0xFF;
    i.endpoint = block->endpoints[a].data();
    for (std::uint8_t e = 0; e < spec.alt[a].endpoints; ++e) {
      libusb_endpoint_descriptor& ep = block->endpoints[a][e];
      ep.bLength = LIBUSB_DT_ENDPOINT_SIZE;
      ep.bDescriptorType = LIBUSB_DT_ENDPOINT;
      ep.bEndpointAddress = spec.alt[a].ep[e].address;
      ep.bmAttributes = spec.alt[a].ep[e].attributes;
      ep.wMaxPacketSize = spec.alt[a].ep[e].max_packet;
      ep.bInterval = spec.alt[a].ep[e].interval;
    }
  }
  return &block->config;
}

// The raw descriptor bytes a GET_DESCRIPTOR control request returns.
struct DescriptorBytes {
  std::array<unsigned char, 512> bytes{};
  std::size_t size = 0;
  void put(std::initializer_list<unsigned> values) noexcept {
    for (const unsigned v : values) {
      if (size < bytes.size()) bytes[size++] = static_cast<unsigned char>(v);
    }
  }
  void u16(unsigned v) noexcept { put({v & 0xFFU, v >> 8}); }
};

std::size_t raw_descriptor(const libusb_device& d, std::uint16_t value, std::uint16_t langid,
                           unsigned char* out, std::size_t size) {
  DescriptorBytes b;
  const auto type = static_cast<std::uint8_t>(value >> 8);
  const auto index = static_cast<std::uint8_t>(value & 0xFF);
  if (type == LIBUSB_DT_DEVICE) {
    const libusb_device_descriptor& x = d.descriptor;
    b.put({x.bLength, x.bDescriptorType});
    b.u16(x.bcdUSB);
    b.put({x.bDeviceClass, x.bDeviceSubClass, x.bDeviceProtocol, x.bMaxPacketSize0});
    b.u16(x.idVendor);
    b.u16(x.idProduct);
    b.u16(x.bcdDevice);
    b.put({x.iManufacturer, x.iProduct, x.iSerialNumber, x.bNumConfigurations});
  } else if (type == LIBUSB_DT_CONFIG && index == 0) {
    const InterfaceSpec& spec = d.interface;
    b.put({LIBUSB_DT_CONFIG_SIZE, LIBUSB_DT_CONFIG});
    b.u16(total_length(spec));
    b.put({1, 1, 0, d.config_attributes, d.max_power});
    for (std::uint8_t a = 0; a < spec.alts; ++a) {
      const unsigned sub = spec.interface_class == LIBUSB_CLASS_HUB ? 0 : 0xFF;
      b.put({LIBUSB_DT_INTERFACE_SIZE, LIBUSB_DT_INTERFACE, 0, a, spec.alt[a].endpoints,
             spec.interface_class, sub, sub, 0});
      for (std::uint8_t e = 0; e < spec.alt[a].endpoints; ++e) {
        const EndpointSpec& ep = spec.alt[a].ep[e];
        b.put({LIBUSB_DT_ENDPOINT_SIZE, LIBUSB_DT_ENDPOINT, ep.address, ep.attributes});
        b.u16(ep.max_packet);
        b.put({ep.interval});
      }
    }
  } else if (type == LIBUSB_DT_STRING && index == 0) {
    b.put({4, LIBUSB_DT_STRING, 0x09, 0x04});  // English (US)
  } else if (type == LIBUSB_DT_STRING && index < d.strings.size() && !d.strings[index].empty() &&
             langid == 0x0409) {
    const std::string& s = d.strings[index];
    b.put({static_cast<unsigned>(std::min<std::size_t>(2 + 2 * s.size(), 254)), LIBUSB_DT_STRING});
    for (const char ch : s) b.u16(static_cast<unsigned char>(ch));
  } else {
    return SIZE_MAX;  // no such descriptor: the device stalls
  }
  const std::size_t n = std::min(size, b.size);
  std::memcpy(out, b.bytes.data(), n);
  return n;
}

bool handle_valid(const World& w, const libusb_device_handle* h) noexcept {
  return h != nullptr && std::find(w.handles.begin(), w.handles.end(), h) != w.handles.end();
}

const EndpointSpec* find_endpoint(const libusb_device& d, std::uint8_t address, int alt) noexcept {
  for (std::uint8_t a = 0; a < d.interface.alts; ++a) {
    if (alt >= 0 && a != alt) continue;
    for (std::uint8_t e = 0; e < d.interface.alt[a].endpoints; ++e) {
      if (d.interface.alt[a].ep[e].address == address) return &d.interface.alt[a].ep[e];
    }
  }
  return nullptr;
}

// ----------------------------------------------------------------------------------------------
// Simulated time and isochronous transfers.

std::int64_t wall_ns(SteadyTime t) noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

// The wall time at which simulated time t may be reached (realtime pacing).
SteadyTime wall_for(const World& w, std::int64_t t) noexcept {
  return w.anchor_wall + std::chrono::nanoseconds(t - w.anchor_sim_ns);
}

// A slow host lets simulated time lag; it then catches up by at most MAX_LAG_NS in a burst.
void reanchor(World& w) noexcept {
  const SteadyTime now = std::chrono::steady_clock::now();
  if (wall_ns(now) - wall_ns(wall_for(w, w.now_ns)) > MAX_LAG_NS) {
    w.anchor_sim_ns = w.now_ns;
    w.anchor_wall = now - std::chrono::nanoseconds(MAX_LAG_NS);
  }
}

void fill_packet(World& w, EndpointQueue& q, libusb_transfer* t) {
  TransferState& s = state_of(t);
  SimKinectDevice& sim = *w.kinects[q.kinect].device;
  libusb_iso_packet_descriptor& p = t->iso_packet_desc[s.filled];
  const std::size_t length =
      sim.iso_packet(q.endpoint, s.first_mf + s.filled, std::span<std::byte>(w.scratch));
  if (length > p.length || s.offset + length > static_cast<std::size_t>(t->length)) {
    p.actual_length = 0;
    p.status = LIBUSB_TRANSFER_OVERFLOW;
  } else {
    std::memcpy(t->buffer + s.offset, w.scratch.data(), length);
    p.actual_length = static_cast<unsigned int>(length);
    p.status = LIBUSB_TRANSFER_COMPLETED;
  }
  s.offset += p.length;  // packet i sits at the sum of the lengths before it: not packed
  ++s.filled;
}

// Generates the packets of every microframe that has fully elapsed by now.
void fill_until_now(World& w) {
  const std::int64_t limit = w.now_ns / USB_MICROFRAME_NS;  // first microframe not yet over
  for (EndpointQueue& q : w.queues) {
    for (libusb_transfer* t : q.pending) {
      TransferState& s = state_of(t);
      while (s.filled < t->num_iso_packets && s.first_mf + s.filled < limit) fill_packet(w, q, t);
      if (s.filled < t->num_iso_packets) break;
    }
  }
}

void advance(World& w, std::int64_t t) {
  if (t > w.now_ns) w.now_ns = t;
  fill_until_now(w);
}

std::int64_t completion_ns(libusb_transfer* t) noexcept {
  return (state_of(t).first_mf + t->num_iso_packets) * USB_MICROFRAME_NS;
}

std::int64_t next_completion(const World& w) noexcept {
  std::int64_t next = NEVER;
  for (const EndpointQueue& q : w.queues) {
    if (!q.pending.empty()) next = std::min(next, completion_ns(q.pending.front()));
  }
  return next;
}

// Takes every transfer that is done now (cancelled ones first, then in completion order).
void take_done(World& w, std::vector<libusb_transfer*>& done) {
  for (libusb_transfer* t : w.cancelled) {
    TransferState& s = state_of(t);
    for (int i = s.filled; i < t->num_iso_packets; ++i) {
      t->iso_packet_desc[i].actual_length = 0;
      t->iso_packet_desc[i].status = LIBUSB_TRANSFER_CANCELLED;
    }
    t->status = LIBUSB_TRANSFER_CANCELLED;
    t->actual_length = 0;
    s.in_flight = false;
    done.push_back(t);
  }
  w.cancelled.clear();
  for (;;) {
    EndpointQueue* first = nullptr;
    for (EndpointQueue& q : w.queues) {
      if (q.pending.empty() || completion_ns(q.pending.front()) > w.now_ns) continue;
      if (first == nullptr ||
          completion_ns(q.pending.front()) < completion_ns(first->pending.front()))
        first = &q;
    }
    if (first == nullptr) return;
    libusb_transfer* t = first->pending.front();
    first->pending.pop_front();
    int total = 0;
    for (int i = 0; i < t->num_iso_packets; ++i)
      total += static_cast<int>(t->iso_packet_desc[i].actual_length);
    t->status = LIBUSB_TRANSFER_COMPLETED;  // iso: per-packet statuses carry the details
    t->actual_length = total;
    state_of(t).in_flight = false;
    done.push_back(t);
  }
}

void run_callbacks(const std::vector<libusb_transfer*>& done) {
  for (libusb_transfer* t : done) {
    const std::uint8_t flags = t->flags;
    if (t->callback != nullptr) t->callback(t);
    // LIBUSB_TRANSFER_FREE_TRANSFER: the callback may not touch the transfer again after this.
    if ((flags & LIBUSB_TRANSFER_FREE_TRANSFER) != 0) libusb_free_transfer(t);
  }
}

// One round of event handling: blocks until something completes or the timeout passes.
int handle_events(libusb_context*, const timeval* tv, int* completed) {
  if (completed != nullptr && *completed != 0) return LIBUSB_SUCCESS;
  std::int64_t timeout_ns = 60'000'000'000;
  if (tv != nullptr) {
    if (tv->tv_sec < 0 || tv->tv_usec < 0 || tv->tv_usec >= 1'000'000)
      return LIBUSB_ERROR_INVALID_PARAM;
    timeout_ns = static_cast<std::int64_t>(tv->tv_sec) * 1'000'000'000 +
                 static_cast<std::int64_t>(tv->tv_usec) * 1'000;
  }
  std::vector<libusb_transfer*> done;
  {
    std::unique_lock lock(g_mutex);
    if (g_world == nullptr) return LIBUSB_ERROR_OTHER;
    World& w = *g_world;
    const SteadyTime call_wall = std::chrono::steady_clock::now();
    const SteadyTime wall_deadline = call_wall + std::chrono::nanoseconds(timeout_ns);
    if (w.realtime) reanchor(w);
    const std::int64_t call_sim = w.now_ns;
    for (;;) {
      take_done(w, done);
      if (!done.empty()) break;
      if (completed != nullptr && *completed != 0) break;
      const std::int64_t next = next_completion(w);
      if (next == NEVER) {  // nothing in flight: wait for a submission, as a real bus would
        if (timeout_ns == 0 || g_cv.wait_until(lock, wall_deadline) == std::cv_status::timeout)
          break;
        continue;
      }
      if (!w.realtime) {  // as fast as possible: jump to the next completion
        advance(w, next);
        continue;
      }
      const SteadyTime now = std::chrono::steady_clock::now();
      const std::int64_t reachable = std::max(
          call_sim + timeout_ns, w.anchor_sim_ns + (wall_ns(now) - wall_ns(w.anchor_wall)));
      const std::int64_t target = std::min(next, reachable);
      const SteadyTime target_wall = wall_for(w, target);
      if (now < target_wall) {
        g_cv.wait_until(lock, target_wall);  // a submit or cancel wakes us to recompute
        continue;
      }
      advance(w, target);
      if (target < next) break;  // timed out
    }
  }
  run_callbacks(done);
  return LIBUSB_SUCCESS;
}

// ----------------------------------------------------------------------------------------------
// The JACO's interrupt pipes. The arm lives in real time whatever the pace (README "JACO"): its
// driver times its 10 ms cycle and its watchdog on the wall clock, so every JACO transfer first
// brings the shared simulated clock up to the wall clock, and its 1 ms latency (and an IN's
// timeout) is waited on the wall clock, with the mutex released.

void catch_up_with_wall(World& w) {
  reanchor(w);  // after a long idle spell: MAX_LAG_NS behind the wall clock, as realtime does
  advance(w,
          w.anchor_sim_ns + (wall_ns(std::chrono::steady_clock::now()) - wall_ns(w.anchor_wall)));
}

// Waits until the wall clock reaches `until` or `done()`; false if the handle died meanwhile.
template <class Done>
bool wait_wall(std::unique_lock<std::mutex>& lock, libusb_device_handle* h, SteadyTime until,
               Done done) {
  while (!done() && std::chrono::steady_clock::now() < until) {
    g_cv.wait_until(lock, until);
    if (g_world == nullptr || !handle_valid(*g_world, h)) return false;
  }
  return true;
}

int jaco_transfer(std::unique_lock<std::mutex>& lock, libusb_device_handle* h,
                  unsigned char endpoint, unsigned char* data, int length, int* transferred,
                  unsigned int timeout) {
  namespace jaco = orthoflow::drivers::jaco;
  const std::size_t index = h->device->jaco;
  if (!h->claimed || (endpoint != jaco::EP_OUT && endpoint != jaco::EP_IN))
    return LIBUSB_ERROR_NOT_FOUND;
  if (length > 0 && data == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  const auto arm = [&]() -> SimJacoArm& { return *g_world->jacos[index].arm; };
  // The end of a transfer: simulated time at least `at_least` and up with the wall clock.
  const auto finish = [&](std::int64_t at_least) {
    catch_up_with_wall(*g_world);
    advance(*g_world, at_least);
    arm().step(g_world->now_ns);
  };
  const auto latency = std::chrono::nanoseconds(JACO_LATENCY_NS);
  catch_up_with_wall(*g_world);
  const std::int64_t start = g_world->now_ns;
  const SteadyTime start_wall = std::chrono::steady_clock::now();
  if (endpoint == jaco::EP_OUT) {  // whole packets only, as SimJacoTransport: nothing sent
    if (length != static_cast<int>(jaco::PACKET_BYTES)) return LIBUSB_ERROR_INVALID_PARAM;
    jaco::Packet packet{};
    std::memcpy(packet.data(), data, packet.size());
    if (!wait_wall(lock, h, start_wall + latency, [] { return false; }))
      return LIBUSB_ERROR_NO_DEVICE;
    finish(start + JACO_LATENCY_NS);
    arm().receive(packet, g_world->now_ns);  // it reaches the arm at the end of the latency
    g_cv.notify_all();                       // an IN may wait on another thread
    *transferred = length;
    return LIBUSB_SUCCESS;
  }
  const std::int64_t wait =
      timeout == 0 ? INFINITE_WAIT_NS : static_cast<std::int64_t>(timeout) * 1'000'000;
  if (!wait_wall(lock, h, start_wall + std::chrono::nanoseconds(wait),
                 [&] { return arm().has_reply(); }))
    return LIBUSB_ERROR_NO_DEVICE;
  if (!arm().has_reply()) {
    finish(start + wait);
    return LIBUSB_ERROR_TIMEOUT;
  }
  catch_up_with_wall(*g_world);
  const std::int64_t from = std::max(start, g_world->now_ns);
  const jaco::Packet reply = arm().take_reply();  // taken now: no other reader can get it
  if (!wait_wall(lock, h, std::chrono::steady_clock::now() + latency, [] { return false; }))
    return LIBUSB_ERROR_NO_DEVICE;
  finish(from + JACO_LATENCY_NS);
  const int n = std::min(length, static_cast<int>(reply.size()));
  std::memcpy(data, reply.data(), static_cast<std::size_t>(n));
  *transferred = n;
  // A buffer under 64 bytes overflows (its part of the packet is kept, the rest is lost).
  return n < static_cast<int>(reply.size()) ? LIBUSB_ERROR_OVERFLOW : LIBUSB_SUCCESS;
}

// ----------------------------------------------------------------------------------------------
// Start-up.

int init_world(libusb_context* ctx) {
  auto kinects_result = orthoflow::sim_libusb::kinects_from_env();
  if (!kinects_result) {
    std::fprintf(stderr, "sim_libusb: %s: %s\n", orthoflow::sim_libusb::ENV_KINECT,
                 kinects_result.error().c_str());
    return LIBUSB_ERROR_INVALID_PARAM;
  }
  auto jacos_result = orthoflow::sim_libusb::jacos_from_env(*kinects_result);
  if (!jacos_result) {
    std::fprintf(stderr, "sim_libusb: %s: %s\n", orthoflow::sim_libusb::ENV_JACO,
                 jacos_result.error().c_str());
    return LIBUSB_ERROR_INVALID_PARAM;
  }
  const char* pace = std::getenv(orthoflow::sim_libusb::ENV_PACE);
  auto pace_result = orthoflow::sim_libusb::parse_pace(pace == nullptr ? "" : pace);
  if (!pace_result) {
    std::fprintf(stderr, "sim_libusb: %s: %s\n", orthoflow::sim_libusb::ENV_PACE,
                 pace_result.error().c_str());
    return LIBUSB_ERROR_INVALID_PARAM;
  }
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr) {
    auto w = std::make_unique<World>();
    w->realtime = *pace_result;
    const char* trace_env = std::getenv(orthoflow::sim_libusb::ENV_TRACE);
    w->trace = trace_env != nullptr && trace_env[0] != '\0' && trace_env[0] != '0';
    w->anchor_wall = std::chrono::steady_clock::now();
    build_bus(*w, std::move(kinects_result).value(), std::move(jacos_result).value());
    g_world = w.release();
    trace(*g_world, "init: %zu Kinect(s), %zu JACO(s), %zu devices, pace %s",
          g_world->kinects.size(), g_world->jacos.size(), g_world->devices.size(),
          g_world->realtime ? "realtime" : "max");
  }
  ++g_world->contexts;
  (void)ctx;
  return LIBUSB_SUCCESS;
}

void exit_world() {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || --g_world->contexts > 0) return;
  for (libusb_device_handle* h : g_world->handles) delete h;
  delete g_world;  // transfers still in flight are the program's bug: they are left alone
  g_world = nullptr;
}

std::string error_of(const char* what) { return std::string("sim_libusb: ") + what; }

}  // namespace

// ================================================================================================
// The exported libusb-1.0 API.

extern "C" {

int LIBUSB_CALL libusb_init(libusb_context** ctx) {
  try {
    libusb_context* c = ctx == nullptr ? &g_default_context : new libusb_context{};
    const int r = init_world(c);
    if (r != LIBUSB_SUCCESS) {
      if (ctx != nullptr) delete c;
      return r;
    }
    if (ctx != nullptr) {
      *ctx = c;
    } else {
      std::lock_guard lock(g_mutex);
      ++g_default_refs;
    }
    return LIBUSB_SUCCESS;
  } catch (...) {
    std::fprintf(stderr, "%s\n", error_of("libusb_init failed").c_str());
    return LIBUSB_ERROR_NO_MEM;
  }
}

void LIBUSB_CALL libusb_exit(libusb_context* ctx) {
  if (ctx == nullptr || ctx == &g_default_context) {
    {
      std::lock_guard lock(g_mutex);
      if (g_default_refs == 0) return;
      --g_default_refs;
    }
  } else {
    delete ctx;
  }
  exit_world();
}

void LIBUSB_CALL libusb_set_debug(libusb_context*, int) {}

void LIBUSB_CALL libusb_set_log_cb(libusb_context*, libusb_log_cb, int) {}

int LIBUSB_CALL libusb_set_option(libusb_context*, enum libusb_option, ...) {
  return LIBUSB_SUCCESS;
}

const struct libusb_version* LIBUSB_CALL libusb_get_version(void) {
  static const libusb_version version{1, 0, 26, 0, "-sim", "orthoflow sim_libusb"};
  return &version;
}

int LIBUSB_CALL libusb_has_capability(uint32_t capability) {
  return capability == LIBUSB_CAP_HAS_CAPABILITY ? 1 : 0;
}

int LIBUSB_CALL libusb_setlocale(const char*) { return LIBUSB_SUCCESS; }

const char* LIBUSB_CALL libusb_error_name(int code) {
  switch (code) {
    case LIBUSB_SUCCESS:
      return "LIBUSB_SUCCESS / LIBUSB_TRANSFER_COMPLETED";
    case LIBUSB_ERROR_IO:
      return "LIBUSB_ERROR_IO";
    case LIBUSB_ERROR_INVALID_PARAM:
      return "LIBUSB_ERROR_INVALID_PARAM";
    case LIBUSB_ERROR_ACCESS:
      return "LIBUSB_ERROR_ACCESS";
    case LIBUSB_ERROR_NO_DEVICE:
      return "LIBUSB_ERROR_NO_DEVICE";
    case LIBUSB_ERROR_NOT_FOUND:
      return "LIBUSB_ERROR_NOT_FOUND";
    case LIBUSB_ERROR_BUSY:
      return "LIBUSB_ERROR_BUSY";
    case LIBUSB_ERROR_TIMEOUT:
      return "LIBUSB_ERROR_TIMEOUT";
    case LIBUSB_ERROR_OVERFLOW:
      return "LIBUSB_ERROR_OVERFLOW";
    case LIBUSB_ERROR_PIPE:
      return "LIBUSB_ERROR_PIPE";
    case LIBUSB_ERROR_INTERRUPTED:
      return "LIBUSB_ERROR_INTERRUPTED";
    case LIBUSB_ERROR_NO_MEM:
      return "LIBUSB_ERROR_NO_MEM";
    case LIBUSB_ERROR_NOT_SUPPORTED:
      return "LIBUSB_ERROR_NOT_SUPPORTED";
    case LIBUSB_ERROR_OTHER:
      return "LIBUSB_ERROR_OTHER";
    case LIBUSB_TRANSFER_ERROR:
      return "LIBUSB_TRANSFER_ERROR";
    case LIBUSB_TRANSFER_TIMED_OUT:
      return "LIBUSB_TRANSFER_TIMED_OUT";
    case LIBUSB_TRANSFER_CANCELLED:
      return "LIBUSB_TRANSFER_CANCELLED";
    case LIBUSB_TRANSFER_STALL:
      return "LIBUSB_TRANSFER_STALL";
    case LIBUSB_TRANSFER_NO_DEVICE:
      return "LIBUSB_TRANSFER_NO_DEVICE";
    case LIBUSB_TRANSFER_OVERFLOW:
      return "LIBUSB_TRANSFER_OVERFLOW";
    default:
      return "**UNKNOWN**";
  }
}

const char* LIBUSB_CALL libusb_strerror(int code) {
  switch (code) {
    case LIBUSB_SUCCESS:
      return "Success";
    case LIBUSB_ERROR_IO:
      return "Input/Output Error";
    case LIBUSB_ERROR_INVALID_PARAM:
      return "Invalid parameter";
    case LIBUSB_ERROR_ACCESS:
      return "Access denied (insufficient permissions)";
    case LIBUSB_ERROR_NO_DEVICE:
      return "No such device (it may have been disconnected)";
    case LIBUSB_ERROR_NOT_FOUND:
      return "Entity not found";
    case LIBUSB_ERROR_BUSY:
      return "Resource busy";
    case LIBUSB_ERROR_TIMEOUT:
      return "Operation timed out";
    case LIBUSB_ERROR_OVERFLOW:
      return "Overflow";
    case LIBUSB_ERROR_PIPE:
      return "Pipe error";
    case LIBUSB_ERROR_INTERRUPTED:
      return "System call interrupted (perhaps due to signal)";
    case LIBUSB_ERROR_NO_MEM:
      return "Insufficient memory";
    case LIBUSB_ERROR_NOT_SUPPORTED:
      return "Operation not supported or unimplemented on this platform";
    default:
      return "Other error";
  }
}

// --- devices ------------------------------------------------------------------------------------

ssize_t LIBUSB_CALL libusb_get_device_list(libusb_context*, libusb_device*** list) {
  if (list == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr) return LIBUSB_ERROR_OTHER;
  const std::size_t n = g_world->devices.size();
  auto** out = static_cast<libusb_device**>(std::calloc(n + 1, sizeof(libusb_device*)));
  if (out == nullptr) return LIBUSB_ERROR_NO_MEM;
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = g_world->devices[i].get();
    ++out[i]->refs;
  }
  *list = out;
  return static_cast<ssize_t>(n);
}

void LIBUSB_CALL libusb_free_device_list(libusb_device** list, int unref_devices) {
  if (list == nullptr) return;
  if (unref_devices != 0) {
    for (libusb_device** d = list; *d != nullptr; ++d) --(*d)->refs;
  }
  std::free(list);
}

libusb_device* LIBUSB_CALL libusb_ref_device(libusb_device* dev) {
  if (dev != nullptr) ++dev->refs;
  return dev;
}

// Devices live as long as the simulated bus (until the last libusb_exit): counts are kept only.
void LIBUSB_CALL libusb_unref_device(libusb_device* dev) {
  if (dev != nullptr) --dev->refs;
}

int LIBUSB_CALL libusb_get_device_descriptor(libusb_device* dev,
                                             struct libusb_device_descriptor* desc) {
  if (dev == nullptr || desc == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  *desc = dev->descriptor;
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_get_active_config_descriptor(libusb_device* dev,
                                                    struct libusb_config_descriptor** config) {
  if (dev == nullptr || config == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  try {
    *config = make_config(*dev);
  } catch (...) { return LIBUSB_ERROR_NO_MEM; }
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_get_config_descriptor(libusb_device* dev, uint8_t config_index,
                                             struct libusb_config_descriptor** config) {
  if (config_index != 0) return LIBUSB_ERROR_NOT_FOUND;
  return libusb_get_active_config_descriptor(dev, config);
}

int LIBUSB_CALL libusb_get_config_descriptor_by_value(libusb_device* dev, uint8_t value,
                                                      struct libusb_config_descriptor** config) {
  if (value != 1) return LIBUSB_ERROR_NOT_FOUND;
  return libusb_get_active_config_descriptor(dev, config);
}

void LIBUSB_CALL libusb_free_config_descriptor(struct libusb_config_descriptor* config) {
  delete reinterpret_cast<ConfigBlock*>(config);
}

int LIBUSB_CALL libusb_get_bos_descriptor(libusb_device_handle*, struct libusb_bos_descriptor**) {
  return LIBUSB_ERROR_PIPE;  // a USB 2.0 device without a BOS descriptor
}

void LIBUSB_CALL libusb_free_bos_descriptor(struct libusb_bos_descriptor*) {}

uint8_t LIBUSB_CALL libusb_get_bus_number(libusb_device* dev) {
  return dev == nullptr ? 0 : dev->bus;
}

uint8_t LIBUSB_CALL libusb_get_port_number(libusb_device* dev) {
  return dev == nullptr || dev->depth == 0 ? 0 : dev->ports[dev->depth - 1];
}

int LIBUSB_CALL libusb_get_port_numbers(libusb_device* dev, uint8_t* port_numbers,
                                        int port_numbers_len) {
  if (dev == nullptr || port_numbers == nullptr || port_numbers_len <= 0)
    return LIBUSB_ERROR_INVALID_PARAM;
  if (port_numbers_len < dev->depth) return LIBUSB_ERROR_OVERFLOW;
  std::copy(dev->ports.begin(), dev->ports.begin() + dev->depth, port_numbers);
  return dev->depth;
}

int LIBUSB_CALL libusb_get_port_path(libusb_context*, libusb_device* dev, uint8_t* path,
                                     uint8_t path_length) {
  return libusb_get_port_numbers(dev, path, path_length);
}

libusb_device* LIBUSB_CALL libusb_get_parent(libusb_device* dev) {
  return dev == nullptr ? nullptr : dev->parent;
}

uint8_t LIBUSB_CALL libusb_get_device_address(libusb_device* dev) {
  return dev == nullptr ? 0 : dev->address;
}

int LIBUSB_CALL libusb_get_device_speed(libusb_device* dev) {
  return dev != nullptr && dev->kind == Kind::JACO ? LIBUSB_SPEED_FULL : LIBUSB_SPEED_HIGH;
}

int LIBUSB_CALL libusb_get_max_packet_size(libusb_device* dev, unsigned char endpoint) {
  if (dev == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  const EndpointSpec* ep = find_endpoint(*dev, endpoint, -1);
  return ep == nullptr ? static_cast<int>(LIBUSB_ERROR_NOT_FOUND) : ep->max_packet;
}

int LIBUSB_CALL libusb_get_max_iso_packet_size(libusb_device* dev, unsigned char endpoint) {
  if (dev == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  const EndpointSpec* ep = find_endpoint(*dev, endpoint, -1);
  if (ep == nullptr) return LIBUSB_ERROR_NOT_FOUND;
  const int bytes = ep->max_packet & 0x07FF;
  const int type = ep->attributes & 0x03;
  if (type == LIBUSB_TRANSFER_TYPE_ISOCHRONOUS || type == LIBUSB_TRANSFER_TYPE_INTERRUPT)
    return bytes * (1 + ((ep->max_packet >> 11) & 3));  // 0x0BC0: 2 x 960 = 1920
  return bytes;
}

// --- handles ------------------------------------------------------------------------------------

int LIBUSB_CALL libusb_open(libusb_device* dev, libusb_device_handle** dev_handle) {
  if (dev == nullptr || dev_handle == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr) return LIBUSB_ERROR_OTHER;
  try {
    auto* h = new libusb_device_handle{};
    h->device = dev;
    g_world->handles.push_back(h);
    ++dev->refs;
    *dev_handle = h;
  } catch (...) { return LIBUSB_ERROR_NO_MEM; }
  trace(*g_world, "open bus %u address %u (%04x:%04x)", dev->bus, dev->address,
        dev->descriptor.idVendor, dev->descriptor.idProduct);
  return LIBUSB_SUCCESS;
}

libusb_device_handle* LIBUSB_CALL libusb_open_device_with_vid_pid(libusb_context*,
                                                                  uint16_t vendor_id,
                                                                  uint16_t product_id) {
  libusb_device* match = nullptr;
  {
    std::lock_guard lock(g_mutex);
    if (g_world == nullptr) return nullptr;
    for (const auto& d : g_world->devices) {
      if (d->descriptor.idVendor == vendor_id && d->descriptor.idProduct == product_id) {
        match = d.get();
        break;
      }
    }
  }
  libusb_device_handle* h = nullptr;
  if (match == nullptr || libusb_open(match, &h) != LIBUSB_SUCCESS) return nullptr;
  return h;
}

void LIBUSB_CALL libusb_close(libusb_device_handle* dev_handle) {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return;
  World& w = *g_world;
  libusb_device& d = *dev_handle->device;
  // Transfers still in flight on a closed handle never complete (closing them is a bug in libusb
  // too); they are dropped so that the simulator never writes into memory the program may free.
  for (EndpointQueue& q : w.queues) {
    const auto n = q.pending.size();
    std::erase_if(q.pending, [&](libusb_transfer* t) {
      if (t->dev_handle != dev_handle) return false;
      state_of(t).in_flight = false;
      return true;
    });
    if (n != q.pending.size())
      std::fprintf(stderr, "sim_libusb: libusb_close with %zu transfer(s) in flight\n",
                   n - q.pending.size());
  }
  std::erase_if(w.cancelled, [&](libusb_transfer* t) { return t->dev_handle == dev_handle; });
  if (d.kind == Kind::FUNCTION && dev_handle->claimed)
    w.kinects[d.kinect].claimed_by[static_cast<std::size_t>(d.function)] = nullptr;
  if (d.kind == Kind::JACO && dev_handle->claimed) w.jacos[d.jaco].claimed_by = nullptr;
  std::erase(w.handles, dev_handle);
  --d.refs;
  trace(w, "close bus %u address %u", d.bus, d.address);
  delete dev_handle;
}

libusb_device* LIBUSB_CALL libusb_get_device(libusb_device_handle* dev_handle) {
  return dev_handle == nullptr ? nullptr : dev_handle->device;
}

int LIBUSB_CALL libusb_get_configuration(libusb_device_handle* dev_handle, int* config) {
  if (dev_handle == nullptr || config == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  *config = 1;
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_set_configuration(libusb_device_handle* dev_handle, int configuration) {
  if (dev_handle == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  return configuration == 1 || configuration == -1 ? LIBUSB_SUCCESS : LIBUSB_ERROR_NOT_FOUND;
}

int LIBUSB_CALL libusb_claim_interface(libusb_device_handle* dev_handle, int interface_number) {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  if (interface_number != 0) return LIBUSB_ERROR_NOT_FOUND;
  if (dev_handle->claimed) return LIBUSB_SUCCESS;
  libusb_device& d = *dev_handle->device;
  if (d.kind == Kind::JACO) {  // one claim per arm
    libusb_device_handle*& owner = g_world->jacos[d.jaco].claimed_by;
    if (owner != nullptr) return LIBUSB_ERROR_BUSY;
    owner = dev_handle;
    dev_handle->claimed = true;
    return LIBUSB_SUCCESS;
  }
  if (d.kind != Kind::FUNCTION) {
    dev_handle->claimed = true;
    return LIBUSB_SUCCESS;
  }
  KinectSlot& slot = g_world->kinects[d.kinect];
  libusb_device_handle*& owner = slot.claimed_by[static_cast<std::size_t>(d.function)];
  if (owner != nullptr) return LIBUSB_ERROR_BUSY;
  if (d.function == KinectFunction::CAMERA && slot.gspca_bound) return LIBUSB_ERROR_BUSY;
  owner = dev_handle;
  dev_handle->claimed = true;
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_release_interface(libusb_device_handle* dev_handle, int interface_number) {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  if (interface_number != 0 || !dev_handle->claimed) return LIBUSB_ERROR_NOT_FOUND;
  libusb_device& d = *dev_handle->device;
  if (d.kind == Kind::FUNCTION)
    g_world->kinects[d.kinect].claimed_by[static_cast<std::size_t>(d.function)] = nullptr;
  if (d.kind == Kind::JACO) g_world->jacos[d.jaco].claimed_by = nullptr;
  dev_handle->claimed = false;
  dev_handle->alt = 0;
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_set_interface_alt_setting(libusb_device_handle* dev_handle,
                                                 int interface_number, int alternate_setting) {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  if (interface_number != 0 || !dev_handle->claimed) return LIBUSB_ERROR_NOT_FOUND;
  if (alternate_setting < 0 || alternate_setting >= dev_handle->device->interface.alts)
    return LIBUSB_ERROR_NOT_FOUND;
  dev_handle->alt = static_cast<std::uint8_t>(alternate_setting);
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_clear_halt(libusb_device_handle* dev_handle, unsigned char endpoint) {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  return find_endpoint(*dev_handle->device, endpoint, -1) == nullptr ? LIBUSB_ERROR_NOT_FOUND
                                                                     : LIBUSB_SUCCESS;
}

// Power-cycle-like for the camera (registers forgotten, streams stopped: the next frame needs a
// new start script), a no-op for the other functions. The handle stays valid (same descriptors).
int LIBUSB_CALL libusb_reset_device(libusb_device_handle* dev_handle) {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  libusb_device& d = *dev_handle->device;
  if (d.kind == Kind::FUNCTION && d.function == KinectFunction::CAMERA) {
    fill_until_now(*g_world);
    g_world->kinects[d.kinect].device->power_cycle();
  }
  if (d.kind == Kind::JACO) {  // a port reset: the arm keeps its state, its pending replies go
    catch_up_with_wall(*g_world);
    SimJacoArm& arm = *g_world->jacos[d.jaco].arm;
    arm.step(g_world->now_ns);
    arm.reset_replies();
  }
  trace(*g_world, "reset bus %u address %u", d.bus, d.address);
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_kernel_driver_active(libusb_device_handle* dev_handle,
                                            int interface_number) {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  if (interface_number != 0) return LIBUSB_ERROR_NOT_FOUND;
  const libusb_device& d = *dev_handle->device;
  return d.kind == Kind::FUNCTION && d.function == KinectFunction::CAMERA &&
                 g_world->kinects[d.kinect].gspca_bound
             ? 1
             : 0;
}

int LIBUSB_CALL libusb_detach_kernel_driver(libusb_device_handle* dev_handle,
                                            int interface_number) {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  if (interface_number != 0) return LIBUSB_ERROR_NOT_FOUND;
  const libusb_device& d = *dev_handle->device;
  if (d.kind != Kind::FUNCTION || d.function != KinectFunction::CAMERA ||
      !g_world->kinects[d.kinect].gspca_bound)
    return LIBUSB_ERROR_NOT_FOUND;
  g_world->kinects[d.kinect].gspca_bound = false;
  dev_handle->detached = true;
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_attach_kernel_driver(libusb_device_handle* dev_handle,
                                            int interface_number) {
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  if (interface_number != 0) return LIBUSB_ERROR_NOT_FOUND;
  const libusb_device& d = *dev_handle->device;
  if (d.kind != Kind::FUNCTION || d.function != KinectFunction::CAMERA)
    return LIBUSB_ERROR_NOT_FOUND;  // no kernel driver for this interface
  KinectSlot& slot = g_world->kinects[d.kinect];
  if (slot.gspca_bound || slot.claimed_by[0] != nullptr) return LIBUSB_ERROR_BUSY;
  slot.gspca_bound = true;
  dev_handle->detached = false;
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_set_auto_detach_kernel_driver(libusb_device_handle*, int) {
  return LIBUSB_ERROR_NOT_SUPPORTED;
}

// --- synchronous transfers ----------------------------------------------------------------------

int LIBUSB_CALL libusb_control_transfer(libusb_device_handle* dev_handle, uint8_t request_type,
                                        uint8_t bRequest, uint16_t wValue, uint16_t wIndex,
                                        unsigned char* data, uint16_t wLength,
                                        unsigned int timeout) {
  std::unique_lock lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  if (wLength > 0 && data == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  World& w = *g_world;
  const libusb_device& d = *dev_handle->device;
  const bool in = (request_type & LIBUSB_ENDPOINT_IN) != 0;
  // Register writes take effect between two microframes: the ones already over are sent first.
  fill_until_now(w);
  int result = LIBUSB_ERROR_PIPE;
  if ((request_type & 0x60) == LIBUSB_REQUEST_TYPE_STANDARD) {
    if (in && bRequest == LIBUSB_REQUEST_GET_DESCRIPTOR) {
      const std::size_t n = raw_descriptor(d, wValue, wIndex, data, wLength);
      if (n != SIZE_MAX) result = static_cast<int>(n);
    } else if (in && bRequest == LIBUSB_REQUEST_GET_STATUS && wLength >= 2) {
      data[0] = (d.config_attributes & 0x40) != 0 ? 1 : 0;  // self-powered
      data[1] = 0;
      result = 2;
    } else if (in && bRequest == LIBUSB_REQUEST_GET_CONFIGURATION && wLength >= 1) {
      data[0] = 1;
      result = 1;
    } else if (!in && (bRequest == LIBUSB_REQUEST_SET_CONFIGURATION ||
                       bRequest == LIBUSB_REQUEST_SET_INTERFACE ||
                       bRequest == LIBUSB_REQUEST_CLEAR_FEATURE)) {
      result = 0;
    }
  } else if (d.kind == Kind::FUNCTION) {
    SimKinectDevice& sim = *w.kinects[d.kinect].device;
    const orthoflow::drivers::UsbControlSetup setup{request_type, bRequest, wValue, wIndex};
    const auto reply =
        sim.control(d.function, setup,
                    std::span<std::byte>(reinterpret_cast<std::byte*>(data), wLength), w.now_ns);
    switch (reply.outcome) {
      case SimControlOutcome::OK:
        result = static_cast<int>(reply.bytes);
        break;
      case SimControlOutcome::PIPE:
        result = LIBUSB_ERROR_PIPE;
        break;
      case SimControlOutcome::TIMEOUT: {  // a lost request: the host waits its whole timeout
        const std::int64_t wait =
            timeout == 0 ? INFINITE_WAIT_NS : static_cast<std::int64_t>(timeout) * 1'000'000;
        if (w.realtime) {
          const SteadyTime until =
              std::chrono::steady_clock::now() + std::chrono::nanoseconds(wait);
          while (g_cv.wait_until(lock, until) != std::cv_status::timeout) {}
        }
        w.now_ns += wait;
        result = LIBUSB_ERROR_TIMEOUT;
        break;
      }
    }
  }
  w.now_ns += CONTROL_LATENCY_NS;
  trace(w, "control %02x %02x %04x %04x len %u -> %d (bus %u address %u)", request_type, bRequest,
        wValue, wIndex, wLength, result, d.bus, d.address);
  return result;
}

namespace {
int bulk_or_interrupt(libusb_device_handle* dev_handle, unsigned char endpoint, unsigned char* data,
                      int length, int* transferred, unsigned int timeout) {
  int ignored = 0;
  if (transferred == nullptr) transferred = &ignored;  // allowed since libusb 1.0.21
  *transferred = 0;
  std::unique_lock lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  if (length < 0) return LIBUSB_ERROR_INVALID_PARAM;
  const libusb_device& d = *dev_handle->device;
  // A JACO's pipes; bulk too: usbfs runs a bulk request on an interrupt endpoint as interrupt.
  if (d.kind == Kind::JACO) {
    const std::uint8_t bus = d.bus;
    const std::uint8_t address = d.address;
    const unsigned command = length >= 6 && (endpoint & LIBUSB_ENDPOINT_IN) == 0
                                 ? static_cast<unsigned>(data[4] | (data[5] << 8))
                                 : 0;
    const int r = jaco_transfer(lock, dev_handle, endpoint, data, length, transferred, timeout);
    if (g_world != nullptr) {
      const unsigned reply = r == LIBUSB_SUCCESS && (endpoint & LIBUSB_ENDPOINT_IN) != 0
                                 ? static_cast<unsigned>(data[4] | (data[5] << 8))
                                 : command;
      trace(*g_world, "interrupt %02x command %u len %d -> %d (bus %u address %u)", endpoint, reply,
            length, r == LIBUSB_SUCCESS ? *transferred : r, bus, address);
    }
    return r;
  }
  trace(*g_world, "bulk/interrupt on %02x refused (bus %u address %u)", endpoint, d.bus, d.address);
  // The audio function is a bootloader whose firmware protocol is not simulated: it stalls.
  if (d.kind == Kind::FUNCTION && d.function == KinectFunction::AUDIO) return LIBUSB_ERROR_PIPE;
  return LIBUSB_ERROR_NOT_FOUND;
}
}  // namespace

int LIBUSB_CALL libusb_bulk_transfer(libusb_device_handle* dev_handle, unsigned char endpoint,
                                     unsigned char* data, int length, int* transferred,
                                     unsigned int timeout) {
  return bulk_or_interrupt(dev_handle, endpoint, data, length, transferred, timeout);
}

int LIBUSB_CALL libusb_interrupt_transfer(libusb_device_handle* dev_handle, unsigned char endpoint,
                                          unsigned char* data, int length, int* transferred,
                                          unsigned int timeout) {
  return bulk_or_interrupt(dev_handle, endpoint, data, length, transferred, timeout);
}

int LIBUSB_CALL libusb_get_string_descriptor_ascii(libusb_device_handle* dev_handle,
                                                   uint8_t desc_index, unsigned char* data,
                                                   int length) {
  if (dev_handle == nullptr || data == nullptr || length <= 0) return LIBUSB_ERROR_INVALID_PARAM;
  if (desc_index == 0) return LIBUSB_ERROR_INVALID_PARAM;  // as libusb: index 0 is the langid
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, dev_handle)) return LIBUSB_ERROR_NO_DEVICE;
  const libusb_device& d = *dev_handle->device;
  if (desc_index >= d.strings.size() || d.strings[desc_index].empty()) return LIBUSB_ERROR_PIPE;
  const std::string& s = d.strings[desc_index];
  const std::size_t n = std::min(s.size(), static_cast<std::size_t>(length - 1));
  std::memcpy(data, s.data(), n);
  data[n] = 0;
  return static_cast<int>(n);
}

// --- asynchronous transfers ---------------------------------------------------------------------

struct libusb_transfer* LIBUSB_CALL libusb_alloc_transfer(int iso_packets) {
  if (iso_packets < 0) return nullptr;
  const std::size_t bytes =
      STATE_BYTES + sizeof(libusb_transfer) +
      static_cast<std::size_t>(iso_packets) * sizeof(libusb_iso_packet_descriptor);
  void* memory = std::calloc(1, bytes);
  if (memory == nullptr) return nullptr;
  new (memory) TransferState{};
  auto* t = reinterpret_cast<libusb_transfer*>(static_cast<char*>(memory) + STATE_BYTES);
  t->num_iso_packets = iso_packets;
  return t;
}

void LIBUSB_CALL libusb_free_transfer(struct libusb_transfer* transfer) {
  if (transfer == nullptr) return;
  {
    std::lock_guard lock(g_mutex);
    if (state_of(transfer).in_flight && g_world != nullptr) {
      std::fprintf(stderr, "sim_libusb: libusb_free_transfer of a transfer in flight\n");
      for (EndpointQueue& q : g_world->queues) std::erase(q.pending, transfer);
      std::erase(g_world->cancelled, transfer);
    }
  }
  if ((transfer->flags & LIBUSB_TRANSFER_FREE_BUFFER) != 0) std::free(transfer->buffer);
  std::free(reinterpret_cast<char*>(transfer) - STATE_BYTES);
}

int LIBUSB_CALL libusb_submit_transfer(struct libusb_transfer* transfer) {
  if (transfer == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr || !handle_valid(*g_world, transfer->dev_handle))
    return LIBUSB_ERROR_NO_DEVICE;
  World& w = *g_world;
  TransferState& s = state_of(transfer);
  if (s.in_flight) return LIBUSB_ERROR_BUSY;
  if (transfer->type != LIBUSB_TRANSFER_TYPE_ISOCHRONOUS) return LIBUSB_ERROR_NOT_SUPPORTED;
  const libusb_device_handle& h = *transfer->dev_handle;
  const libusb_device& d = *h.device;
  const bool camera = d.kind == Kind::FUNCTION && d.function == KinectFunction::CAMERA;
  if (!camera || find_endpoint(d, transfer->endpoint, h.alt) == nullptr)
    return LIBUSB_ERROR_NOT_FOUND;  // also: a K4W camera still in alternate setting 0
  if (transfer->num_iso_packets <= 0 || transfer->buffer == nullptr || transfer->length < 0)
    return LIBUSB_ERROR_INVALID_PARAM;
  long long sum = 0;
  for (int i = 0; i < transfer->num_iso_packets; ++i) sum += transfer->iso_packet_desc[i].length;
  if (sum > transfer->length) return LIBUSB_ERROR_INVALID_PARAM;
  const std::size_t qi =
      d.kinect * 2 + (transfer->endpoint == orthoflow::simulation::KINECT_DEPTH_ENDPOINT ? 1 : 0);
  EndpointQueue& q = w.queues[qi];
  s = TransferState{};
  s.in_flight = true;
  s.queue = qi;
  // Back to back after the transfers already queued, from the next microframe boundary on.
  s.first_mf = std::max(q.next_free_mf, (w.now_ns + USB_MICROFRAME_NS - 1) / USB_MICROFRAME_NS);
  q.next_free_mf = s.first_mf + transfer->num_iso_packets;
  for (int i = 0; i < transfer->num_iso_packets; ++i) {
    transfer->iso_packet_desc[i].actual_length = 0;
    transfer->iso_packet_desc[i].status = LIBUSB_TRANSFER_ERROR;
  }
  transfer->actual_length = 0;
  q.pending.push_back(transfer);
  g_cv.notify_all();
  return LIBUSB_SUCCESS;
}

int LIBUSB_CALL libusb_cancel_transfer(struct libusb_transfer* transfer) {
  if (transfer == nullptr) return LIBUSB_ERROR_INVALID_PARAM;
  std::lock_guard lock(g_mutex);
  if (g_world == nullptr) return LIBUSB_ERROR_NOT_FOUND;
  TransferState& s = state_of(transfer);
  if (!s.in_flight || s.cancelled) return LIBUSB_ERROR_NOT_FOUND;
  EndpointQueue& q = g_world->queues[s.queue];
  const auto it = std::find(q.pending.begin(), q.pending.end(), transfer);
  if (it == q.pending.end()) return LIBUSB_ERROR_NOT_FOUND;
  q.pending.erase(it);
  s.cancelled = true;
  g_world->cancelled.push_back(transfer);
  g_cv.notify_all();
  return LIBUSB_SUCCESS;
}

void LIBUSB_CALL libusb_transfer_set_stream_id(struct libusb_transfer*, uint32_t) {}

uint32_t LIBUSB_CALL libusb_transfer_get_stream_id(struct libusb_transfer*) { return 0; }

// --- events -------------------------------------------------------------------------------------

int LIBUSB_CALL libusb_handle_events_timeout_completed(libusb_context* ctx, struct timeval* tv,
                                                       int* completed) {
  return handle_events(ctx, tv, completed);
}

int LIBUSB_CALL libusb_handle_events_timeout(libusb_context* ctx, struct timeval* tv) {
  return handle_events(ctx, tv, nullptr);
}

int LIBUSB_CALL libusb_handle_events(libusb_context* ctx) {
  return handle_events(ctx, nullptr, nullptr);
}

int LIBUSB_CALL libusb_handle_events_completed(libusb_context* ctx, int* completed) {
  return handle_events(ctx, nullptr, completed);
}

int LIBUSB_CALL libusb_handle_events_locked(libusb_context* ctx, struct timeval* tv) {
  return handle_events(ctx, tv, nullptr);
}

// The event lock of libusb's multi-threaded API: every event handler already serialises on the
// shim's mutex, so these only keep the protocol of callers that use them.
int LIBUSB_CALL libusb_try_lock_events(libusb_context*) { return 0; }
void LIBUSB_CALL libusb_lock_events(libusb_context*) {}
void LIBUSB_CALL libusb_unlock_events(libusb_context*) { g_cv.notify_all(); }
int LIBUSB_CALL libusb_event_handling_ok(libusb_context*) { return 1; }
int LIBUSB_CALL libusb_event_handler_active(libusb_context*) { return 0; }
void LIBUSB_CALL libusb_interrupt_event_handler(libusb_context*) { g_cv.notify_all(); }
void LIBUSB_CALL libusb_lock_event_waiters(libusb_context*) {}
void LIBUSB_CALL libusb_unlock_event_waiters(libusb_context*) {}
int LIBUSB_CALL libusb_wait_for_event(libusb_context*, struct timeval* tv) {
  std::unique_lock lock(g_mutex);
  const auto wait = tv == nullptr
                        ? std::chrono::microseconds(60'000'000)
                        : std::chrono::seconds(tv->tv_sec) + std::chrono::microseconds(tv->tv_usec);
  return g_cv.wait_for(lock, wait) == std::cv_status::timeout ? 1 : 0;
}

int LIBUSB_CALL libusb_get_next_timeout(libusb_context*, struct timeval*) {
  return 0;  // no libusb-side timeouts: handle_events blocks for what it simulates
}

int LIBUSB_CALL libusb_pollfds_handle_timeouts(libusb_context*) { return 1; }

const struct libusb_pollfd** LIBUSB_CALL libusb_get_pollfds(libusb_context*) {
  return static_cast<const libusb_pollfd**>(std::calloc(1, sizeof(libusb_pollfd*)));
}

void LIBUSB_CALL libusb_free_pollfds(const struct libusb_pollfd** pollfds) {
  std::free(static_cast<void*>(pollfds));
}

void LIBUSB_CALL libusb_set_pollfd_notifiers(libusb_context*, libusb_pollfd_added_cb,
                                             libusb_pollfd_removed_cb, void*) {}

int LIBUSB_CALL libusb_hotplug_register_callback(libusb_context*, int, int, int, int, int,
                                                 libusb_hotplug_callback_fn, void*,
                                                 libusb_hotplug_callback_handle*) {
  return LIBUSB_ERROR_NOT_SUPPORTED;
}

void LIBUSB_CALL libusb_hotplug_deregister_callback(libusb_context*,
                                                    libusb_hotplug_callback_handle) {}

}  // extern "C"
