#pragma once
/// @file
/// @brief (internal to drivers/usb/) The one include of libusb-1.0's own header. Only the libusb
/// implementation of the seam includes this file: libusb_call.cpp, libusb_transport.cpp,
/// libusb_iso.cpp and libusb_discovery.cpp (STYLE rule 16; tests/architecture checks it).
#include <libusb-1.0/libusb.h>
