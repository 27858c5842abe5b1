#pragma once
// The system calls the Linux drivers make, behind one small virtual interface, so tests can
// stand in for the kernel (ENODEV on open, EAGAIN, an error frame, an overflow count, a V4L2
// ioctl sequence, a camera unplugged mid-stream) on a machine without the devices. Each call
// behaves like its libc namesake: -1 (or MAP_FAILED) with errno set on failure.
#include <poll.h>
#include <sys/socket.h>
#include <sys/types.h>

#include <cstddef>

namespace epichead::hw {

class Syscalls {
 public:
  virtual ~Syscalls() = default;
  virtual int open(const char* path, int flags);
  virtual int close(int fd);
  virtual int ioctl(int fd, unsigned long request, void* arg);
  virtual int poll(pollfd* fds, nfds_t count, int timeout_ms);
  virtual void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset);
  virtual int munmap(void* address, std::size_t length);
  virtual int socket(int domain, int type, int protocol);
  virtual int bind(int fd, const sockaddr* address, socklen_t length);
  virtual int setsockopt(int fd, int level, int name, const void* value, socklen_t length);
  virtual ssize_t recvmsg(int fd, msghdr* message, int flags);
  virtual ssize_t write(int fd, const void* data, std::size_t size);

  // The real kernel: the drivers' default.
  static Syscalls& real();
};

}  // namespace epichead::hw
