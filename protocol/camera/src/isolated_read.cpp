#include "isolated_read.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include <fmt/format.h>

namespace covtrack {
namespace {

// The child's answer: a camera, or an error whose text follows.
struct Reply {
  bool ok = false;
  int width_px = 0, height_px = 0;
  double numbers[13] = {};  // fx fy cx cy k1 k2 p1 p2 k3, then the four intrinsic sigmas
  std::size_t message_size = 0;
};

void write_all(int fd, const void* data, std::size_t size) {
  const auto* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    p += n, size -= static_cast<std::size_t>(n);
  }
}

[[noreturn]] void answer_and_exit(int fd, const Result<Camera>& r) {
  Reply reply;
  std::string message;
  if (r) {
    const Camera& c = *r;
    reply.ok = true, reply.width_px = c.width_px, reply.height_px = c.height_px;
    const double numbers[13] = {c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3, c.intrinsic_sigmas_px[0],
                                c.intrinsic_sigmas_px[1], c.intrinsic_sigmas_px[2], c.intrinsic_sigmas_px[3]};
    std::memcpy(reply.numbers, numbers, sizeof numbers);
  } else {
    message = r.error().message;
    reply.message_size = message.size();
  }
  write_all(fd, &reply, sizeof reply);
  write_all(fd, message.data(), message.size());
  ::_exit(0);  // no exit handlers, no flushing of buffers the parent owns too
}

Result<Camera> camera_of(const Reply& reply, const std::string& message) {
  if (!reply.ok) return fail(message);
  Camera c;
  c.width_px = reply.width_px, c.height_px = reply.height_px;
  const double* n = reply.numbers;
  c.fx = n[0], c.fy = n[1], c.cx = n[2], c.cy = n[3], c.k1 = n[4], c.k2 = n[5], c.p1 = n[6], c.p2 = n[7], c.k3 = n[8];
  c.intrinsic_sigmas_px = Eigen::Vector4d(n[9], n[10], n[11], n[12]);
  return c;
}

}  // namespace

Result<Camera> read_isolated(const std::function<Result<Camera>()>& read, const std::string& file,
                             std::chrono::milliseconds limit) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return read();
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]), ::close(fds[1]);
    return read();
  }
  if (child == 0) {
    ::close(fds[0]);
    answer_and_exit(fds[1], read());
  }
  ::close(fds[1]);
  std::string bytes;
  const auto deadline = std::chrono::steady_clock::now() + limit;
  bool timed_out = false;
  for (;;) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) {
      timed_out = true;
      break;
    }
    // Rounded up: a wait cut short by rounding would end the read before its limit.
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - now);
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;  // the deadline is checked above
    char buffer[4096];
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // the child has answered and gone
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  if (timed_out) ::kill(child, SIGKILL);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out)
    return fail(fmt::format("{}: OpenCV's reader did not finish within {} s and was stopped: the file is damaged "
                            "(OpenCV 4.6 loops forever on some malformed YAML)",
                            file, std::chrono::duration<double>(limit).count()));
  Reply reply;
  if (bytes.size() < sizeof reply) {
    if (WIFSIGNALED(status))
      return fail(fmt::format("{}: OpenCV's reader crashed on it (signal {}): the file is damaged", file,
                              WTERMSIG(status)));
    return fail(fmt::format("{}: OpenCV's reader ended without an answer", file));
  }
  std::memcpy(&reply, bytes.data(), sizeof reply);
  if (!reply.ok && bytes.size() != sizeof reply + reply.message_size)
    return fail(fmt::format("{}: OpenCV's reader sent a broken answer", file));
  return camera_of(reply, bytes.substr(sizeof reply));
}

}  // namespace covtrack
