#pragma once
// Raw bytes to a console's port (issue 70's hostile clients): what a broken or hostile client sends,
// without an HTTP library's manners, and connections held open without a word.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

namespace raw_http {

inline int connect_to(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&to), sizeof to) == 0) return fd;
  ::close(fd);
  return -1;
}

/// Sends `bytes` to 127.0.0.1:`port`, closes the sending side and reads the answer to its end.
inline std::string send(int port, const std::string& bytes) {
  const int fd = connect_to(port);
  std::string answer;
  if (fd < 0) return answer;
  (void)!::write(fd, bytes.data(), bytes.size());
  ::shutdown(fd, SHUT_WR);
  char buf[512];
  for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) answer.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  return answer;
}

/// `count` connections to the port, connected and silent (close each when done).
inline std::vector<int> hold(int port, int count) {
  std::vector<int> held;
  for (int i = 0; i < count; ++i)
    if (const int fd = connect_to(port); fd >= 0) held.push_back(fd);
  return held;
}

/// Malformed requests, one of each kind a hostile run sends round and round.
inline std::vector<std::string> junk() {
  return {"GARBAGE\r\n\r\n",
          "GET\r\n\r\n",
          "POST /api/blackout HTTP/1.1\r\nContent-Length: -5\r\n\r\n",
          std::string(5000, 'A') + "\r\n\r\n",
          "GET /%00%ff HTTP/1.1\r\n\r\n",
          "POST /api/goto HTTP/1.1\r\nContent-Type: application/json\r\nContent-Length: 3\r\n\r\n{\"t"};
}

/// A body claiming 100 MB.
inline std::string huge_body() {
  return "POST /api/blackout HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: 104857600\r\n\r\n{\"on\": "
         "true}";
}

}  // namespace raw_http
