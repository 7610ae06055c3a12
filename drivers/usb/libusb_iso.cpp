// LibusbTransport: isochronous IN streams over libusb's asynchronous transfers, and the transport's
// destructor (it needs the stream type). Part of the libusb implementation: one of the four files
// that include libusb's header. A stream's transfers are resubmitted from their own completion
// callback, which libusb runs inside event handling (handle_events() or a synchronous call), so
// nothing polls.
#include "drivers/usb/libusb_transport.hpp"

#include "drivers/usb/libusb_api.hpp"

#include <algorithm>
#include <climits>
#include <utility>

#include "core/assert.hpp"
#include "drivers/usb/libusb_call.hpp"

namespace orthoflow::drivers {

struct LibusbIsoStream {
  std::uint32_t device_id = 0;
  std::uint8_t endpoint = 0;
  std::size_t packet_size = 0;
  std::vector<std::byte>
      buffer;  // transfers x packets x packet_size: packet i of a transfer at i x packet_size
  std::vector<libusb_transfer*> transfers;
  UsbIsoCallback on_packet;
  UsbIsoStats stats;
  bool* in_callback = nullptr;  // the owning transport's re-entry guard
  bool stopping = false;
  int drained = 0;  // libusb's `completed` flag for the stop wait: 1 once no transfer is in flight
  LibusbIsoStream() = default;
  LibusbIsoStream(const LibusbIsoStream&) = delete;
  LibusbIsoStream& operator=(const LibusbIsoStream&) = delete;
  // Only ever destroyed with nothing in flight: freeing a transfer the host controller owns
  // corrupts memory.
  ~LibusbIsoStream() {
    for (libusb_transfer* transfer : transfers) libusb_free_transfer(transfer);
  }
};

namespace {

constexpr int ISO_DRAIN_ROUNDS =
    20;  // x ISO_DRAIN_ROUND: how long stop_iso waits for cancelled transfers
constexpr UsbTimeout ISO_DRAIN_ROUND{100};
constexpr std::size_t ISO_MAX_TRANSFERS = 1024;

void deliver_packets(LibusbIsoStream& stream, const libusb_transfer& transfer,
                     UsbPacketStatus transfer_status) {
  const auto* base = reinterpret_cast<const std::byte*>(transfer.buffer);
  const libusb_iso_packet_descriptor* packets = transfer.iso_packet_desc;
  *stream.in_callback = true;
  for (int i = 0; i < transfer.num_iso_packets; ++i) {
    // For iso transfers libusb reports per-packet status; the transfer's own status only says it
    // failed whole.
    const UsbPacketStatus status = transfer_status == UsbPacketStatus::COMPLETED
                                       ? usb_packet_status_from_libusb(packets[i].status)
                                       : transfer_status;
    const bool ok = status == UsbPacketStatus::COMPLETED;
    // Distrust the reported length: never hand out bytes beyond this packet's own slot.
    const std::size_t length =
        ok ? std::min<std::size_t>(packets[i].actual_length, stream.packet_size) : 0;
    ++(ok ? stream.stats.packets_completed : stream.stats.packets_failed);
    stream.stats.bytes_received += length;
    stream.on_packet({base + static_cast<std::size_t>(i) * stream.packet_size, length}, length,
                     status);
  }
  *stream.in_callback = false;
}

void LIBUSB_CALL on_iso_transfer(libusb_transfer* transfer) {
  auto& stream = *static_cast<LibusbIsoStream*>(transfer->user_data);
  const UsbPacketStatus status = usb_packet_status_from_libusb(transfer->status);
  if (!stream.stopping) {
    ++(status == UsbPacketStatus::COMPLETED ? stream.stats.transfers_completed
                                            : stream.stats.transfers_failed);
    deliver_packets(stream, *transfer, status);
  }
  // Resubmit at once, after errors too (KINECT_V1.md 2.1); not once the device is gone, nor after a
  // cancellation stop_iso did not ask for (how some platforms report a disconnect).
  const bool resubmit = !stream.stopping && status != UsbPacketStatus::NO_DEVICE &&
                        status != UsbPacketStatus::CANCELLED;
  if (resubmit &&
      libusb_call("libusb_submit_transfer", [&] { return libusb_submit_transfer(transfer); }))
    return;
  if (resubmit) ++stream.stats.resubmit_failures;
  --stream.stats.transfers_in_flight;
  if (stream.stats.transfers_in_flight == 0) stream.drained = 1;
}

bool valid_iso_request(std::uint8_t endpoint, const UsbIsoConfig& config,
                       const UsbIsoCallback& on_packet) {
  if ((endpoint & LIBUSB_ENDPOINT_IN) == 0 || !on_packet) return false;
  if (config.transfers == 0 || config.packets_per_transfer == 0 || config.packet_size == 0)
    return false;
  // libusb counts a transfer's packets and bytes in int.
  return config.transfers <= ISO_MAX_TRANSFERS && config.packets_per_transfer <= INT_MAX &&
         config.packet_size <= INT_MAX / config.packets_per_transfer;
}

// All buffers and transfers of a stream, allocated here once: nothing is allocated while it runs.
Result<std::unique_ptr<LibusbIsoStream, LibusbIsoStreamDeleter>, UsbError> make_stream(
    libusb_device_handle* handle, std::uint8_t endpoint, const UsbIsoConfig& config) {
  std::unique_ptr<LibusbIsoStream, LibusbIsoStreamDeleter> stream(new LibusbIsoStream());
  stream->endpoint = endpoint;
  stream->packet_size = config.packet_size;
  const std::size_t transfer_bytes = config.packets_per_transfer * config.packet_size;
  stream->buffer.resize(config.transfers * transfer_bytes);
  stream->transfers.reserve(config.transfers);
  for (std::size_t t = 0; t < config.transfers; ++t) {
    libusb_transfer* transfer =
        libusb_alloc_transfer(static_cast<int>(config.packets_per_transfer));
    if (transfer == nullptr) {
      return orthoflow::err(
          UsbError{UsbError::Code::NO_MEM, LIBUSB_ERROR_NO_MEM, "libusb_alloc_transfer"});
    }
    stream->transfers.push_back(transfer);
    auto* bytes = reinterpret_cast<unsigned char*>(stream->buffer.data() + t * transfer_bytes);
    // Timeout 0: an iso transfer completes on the bus schedule, never by timing out.
    libusb_fill_iso_transfer(transfer, handle, endpoint, bytes, static_cast<int>(transfer_bytes),
                             static_cast<int>(config.packets_per_transfer), on_iso_transfer,
                             stream.get(), 0);
    libusb_set_iso_packet_lengths(transfer, static_cast<unsigned int>(config.packet_size));
  }
  return stream;
}

}  // namespace

void LibusbIsoStreamDeleter::operator()(LibusbIsoStream* stream) const noexcept { delete stream; }

LibusbIsoStream* LibusbTransport::find_stream(std::uint32_t device_id,
                                              std::uint8_t endpoint) const noexcept {
  for (const auto& stream : streams_) {
    if (stream->device_id == device_id && stream->endpoint == endpoint) return stream.get();
  }
  return nullptr;
}

Result<void, UsbError> LibusbTransport::start_iso(const UsbDeviceHandle& handle,
                                                  std::uint8_t endpoint, const UsbIsoConfig& config,
                                                  UsbIsoCallback on_packet) {
  check_not_in_callback();
  libusb_device_handle* native = native_handle(handle);
  if (native == nullptr) return orthoflow::err(refused(UsbError::Code::NOT_OPEN, "start_iso"));
  if (!valid_iso_request(endpoint, config, on_packet)) {
    return orthoflow::err(refused(UsbError::Code::INVALID_PARAM, "start_iso"));
  }
  if (find_stream(handle.id(), endpoint) != nullptr)
    return orthoflow::err(refused(UsbError::Code::BUSY, "start_iso"));
  auto stream_result = make_stream(native, endpoint, config);
  if (!stream_result) return orthoflow::err(stream_result.error());
  LibusbIsoStream& stream = **stream_result;
  stream.device_id = handle.id();
  stream.on_packet = std::move(on_packet);
  stream.in_callback = &in_callback_;
  streams_.push_back(std::move(*stream_result));
  for (libusb_transfer* transfer : stream.transfers) {
    auto submit_result =
        libusb_call("libusb_submit_transfer", [&] { return libusb_submit_transfer(transfer); });
    if (!submit_result) {
      (void)stop_stream(stream);  // takes back the transfers already submitted
      return orthoflow::err(submit_result.error());
    }
    ++stream.stats.transfers_in_flight;
  }
  return {};
}

Result<void, UsbError> LibusbTransport::stop_iso(const UsbDeviceHandle& handle,
                                                 std::uint8_t endpoint) {
  check_not_in_callback();
  if (native_handle(handle) == nullptr)
    return orthoflow::err(refused(UsbError::Code::NOT_OPEN, "stop_iso"));
  LibusbIsoStream* stream = find_stream(handle.id(), endpoint);
  if (stream == nullptr) return orthoflow::err(refused(UsbError::Code::NOT_FOUND, "stop_iso"));
  return stop_stream(*stream);
}

Result<UsbIsoStats, UsbError> LibusbTransport::iso_stats(const UsbDeviceHandle& handle,
                                                         std::uint8_t endpoint) const {
  if (native_handle(handle) == nullptr)
    return orthoflow::err(refused(UsbError::Code::NOT_OPEN, "iso_stats"));
  const LibusbIsoStream* stream = find_stream(handle.id(), endpoint);
  if (stream == nullptr) return orthoflow::err(refused(UsbError::Code::NOT_FOUND, "iso_stats"));
  return stream->stats;
}

Result<void, UsbError> LibusbTransport::stop_stream(LibusbIsoStream& stream) {
  stream.stopping = true;
  for (libusb_transfer* transfer : stream.transfers) {
    // NOT_FOUND is expected: the transfer was never submitted, or its completion is already queued.
    (void)libusb_call("libusb_cancel_transfer", [&] { return libusb_cancel_transfer(transfer); });
  }
  drain(stream);
  const auto it = std::find_if(streams_.begin(), streams_.end(),
                               [&](const auto& s) { return s.get() == &stream; });
  OF_ENFORCE(it != streams_.end(), "stop_stream: the stream is not this transport's");
  IsoStreamPtr owned = std::move(*it);
  streams_.erase(it);
  if (owned->stats.transfers_in_flight == 0) return {};  // owned's destructor frees the transfers
  abandoned_streams_.push_back(
      std::move(owned));  // freed by a later handle_events() once they are back
  return orthoflow::err(UsbError{UsbError::Code::TIMEOUT, LIBUSB_ERROR_TIMEOUT, "stop_iso"});
}

void LibusbTransport::stop_streams_of(std::uint32_t device_id) noexcept {
  auto of_device = [device_id](const auto& stream) { return stream->device_id == device_id; };
  for (auto it = std::find_if(streams_.begin(), streams_.end(), of_device); it != streams_.end();
       it = std::find_if(streams_.begin(), streams_.end(), of_device)) {
    (void)stop_stream(**it);  // always removes the stream from streams_
  }
}

void LibusbTransport::drain(LibusbIsoStream& stream) noexcept {
  // Cancellation is asynchronous: each cancelled transfer comes back through its callback during
  // event handling. `drained` lets libusb return as soon as the last one is back; the bound keeps a
  // wedged host controller from hanging shutdown.
  for (int round = 0; round < ISO_DRAIN_ROUNDS && stream.stats.transfers_in_flight > 0; ++round) {
    (void)pump(ISO_DRAIN_ROUND, &stream.drained);
  }
}

bool LibusbTransport::release_all_streams() noexcept {
  while (!streams_.empty()) (void)stop_stream(*streams_.back());
  for (auto& stream : abandoned_streams_) drain(*stream);
  collect_abandoned_streams();
  if (abandoned_streams_.empty()) return true;
  // Transfers the host controller never gave back: leak them (the caller leaks their context too)
  // rather than free memory still in use.
  for (auto& stream : abandoned_streams_) (void)stream.release();
  abandoned_streams_.clear();
  return false;
}

void LibusbTransport::collect_abandoned_streams() noexcept {
  std::erase_if(abandoned_streams_,
                [](const auto& stream) { return stream->stats.transfers_in_flight == 0; });
}

}  // namespace orthoflow::drivers
