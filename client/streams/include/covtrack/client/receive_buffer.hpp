#pragma once
// The socket receive buffer of a udpm:// receiver: what absorbs a burst, or the reader
// being descheduled, before the kernel drops datagrams.
#include <string>

namespace covtrack::client {

struct ReceiveBufferSize {
  int requested = 0;  // bytes: the URL's recv_buf_size, else the receiver's default
  int granted = 0;    // bytes the kernel lets the socket hold (Linux counts double what it sets)
  std::string note;   // non-empty when the kernel capped the request: what to do about it
};

}  // namespace covtrack::client
