#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include "epichead/hw/syscalls.h"

namespace epichead::hw {

int Syscalls::open(const char* path, int flags) { return ::open(path, flags); }
int Syscalls::close(int fd) { return ::close(fd); }
int Syscalls::ioctl(int fd, unsigned long request, void* arg) { return ::ioctl(fd, request, arg); }
int Syscalls::poll(pollfd* fds, nfds_t count, int timeout_ms) { return ::poll(fds, count, timeout_ms); }
void* Syscalls::mmap(std::size_t length, int prot, int flags, int fd, off_t offset) {
  return ::mmap(nullptr, length, prot, flags, fd, offset);
}
int Syscalls::munmap(void* address, std::size_t length) { return ::munmap(address, length); }
int Syscalls::socket(int domain, int type, int protocol) { return ::socket(domain, type, protocol); }
int Syscalls::bind(int fd, const sockaddr* address, socklen_t length) { return ::bind(fd, address, length); }
int Syscalls::setsockopt(int fd, int level, int name, const void* value, socklen_t length) {
  return ::setsockopt(fd, level, name, value, length);
}
ssize_t Syscalls::recvmsg(int fd, msghdr* message, int flags) { return ::recvmsg(fd, message, flags); }
ssize_t Syscalls::write(int fd, const void* data, std::size_t size) { return ::write(fd, data, size); }

Syscalls& Syscalls::real() {
  static Syscalls calls;
  return calls;
}

}  // namespace epichead::hw
