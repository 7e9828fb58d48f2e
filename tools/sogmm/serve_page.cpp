// A minimal HTTP/1.0 responder for one page on the loopback interface: one
// connection at a time, no keep-alive, no dependency beyond POSIX sockets.
// It only has to hand a browser on the same machine one file.
#include "serve_page.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "sigint_cancel.hpp"
#include "sogmm/error.hpp"

namespace sogmm::tools {
namespace {

constexpr std::size_t kMaxRequest = 8192;  // a browser's GET is well under 1 KiB
constexpr int kClientTimeoutSeconds = 5;
constexpr int kPollMs = 200;  // how often the accept loop looks at the SIGINT flag

// Closes the descriptor when the scope ends.
struct Socket {
  int fd;
  explicit Socket(int f) : fd(f) {}
  ~Socket() {
    if (fd >= 0) close(fd);
  }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
};

void send_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = send(fd, data, size, MSG_NOSIGNAL);  // a closed client is no reason to die of SIGPIPE
    if (n < 0 && errno == EINTR && !SigintCancel::requested()) continue;
    if (n <= 0) return;  // the client went away: nothing to do
    data += n;
    size -= static_cast<std::size_t>(n);
  }
}

void respond(int fd, const char* status, const std::string& body, bool with_body, const char* extra = "") {
  char head[512];
  const int n = std::snprintf(head, sizeof head,
                              "HTTP/1.0 %s\r\nContent-Type: %s\r\nContent-Length: %zu\r\n"
                              "Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n%sConnection: close\r\n\r\n",
                              status, std::strncmp(status, "200", 3) == 0 ? "text/html; charset=utf-8" : "text/plain",
                              body.size(), extra);
  send_all(fd, head, static_cast<std::size_t>(n));
  if (with_body) send_all(fd, body.data(), body.size());
}

// The request head (up to the blank line), or "" when the client sent
// nothing complete within the timeout or more than kMaxRequest bytes.
std::string read_head(int fd) {
  std::string head;
  char buf[1024];
  while (head.size() <= kMaxRequest) {
    const ssize_t n = recv(fd, buf, sizeof buf, 0);
    if (n < 0 && errno == EINTR && !SigintCancel::requested()) continue;
    if (n <= 0) return "";
    head.append(buf, static_cast<std::size_t>(n));
    const std::size_t end = head.find("\r\n\r\n");
    if (end != std::string::npos) return head.substr(0, end + 2);
  }
  return "";
}

// The value of header `name` (case-insensitive name, blanks trimmed); found
// says whether the head has it.
std::string header_value(const std::string& head, const std::string& name, bool& found) {
  found = false;
  std::size_t at = head.find("\r\n");
  while (at != std::string::npos && at + 2 < head.size()) {
    const std::size_t begin = at + 2;
    const std::size_t end = head.find("\r\n", begin);
    const std::string line = head.substr(begin, end - begin);
    const std::size_t colon = line.find(':');
    if (colon == name.size() && strncasecmp(line.c_str(), name.c_str(), colon) == 0) {
      std::size_t v = colon + 1;
      while (v < line.size() && (line[v] == ' ' || line[v] == '\t')) ++v;
      std::size_t e = line.size();
      while (e > v && (line[e - 1] == ' ' || line[e - 1] == '\t')) --e;
      found = true;
      return line.substr(v, e - v);
    }
    at = end;
  }
  return "";
}

void answer(int fd, const std::string& page, int port) {
  const std::string head = read_head(fd);
  const std::size_t sp1 = head.find(' ');
  const std::size_t sp2 = sp1 == std::string::npos ? sp1 : head.find(' ', sp1 + 1);
  const std::size_t eol = head.find("\r\n");
  if (head.empty() || sp2 == std::string::npos || sp2 > eol || head.compare(sp2 + 1, 5, "HTTP/") != 0) {
    respond(fd, "400 Bad Request", "bad request\n", true);
    return;
  }
  const std::string method = head.substr(0, sp1);
  std::string path = head.substr(sp1 + 1, sp2 - sp1 - 1);
  path = path.substr(0, path.find('?'));
  const bool get = method == "GET";
  if (!get && method != "HEAD") {
    respond(fd, "405 Method Not Allowed", "only GET and HEAD\n", true, "Allow: GET, HEAD\r\n");
    return;
  }
  bool has_host = false;
  const std::string host = header_value(head, "Host", has_host);
  const std::string p = std::to_string(port);
  if (has_host && host != "127.0.0.1:" + p && host != "localhost:" + p) {
    respond(fd, "403 Forbidden", "unexpected Host header\n", get);
    return;
  }
  if (path != "/" && path != "/index.html") {
    respond(fd, "404 Not Found", "not found: the page is at /\n", get);
    return;
  }
  respond(fd, "200 OK", page, get);
}

}  // namespace

void serve_page(const std::string& page, int port) {
  require(port >= 0 && port <= 65535, ErrorCode::InvalidArgument, "--port must be in 0..65535");
  // Each call's errno is read before anything else can change it (the
  // arguments of require() are evaluated in no fixed order).
  Socket listener(socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (listener.fd < 0) throw Error(ErrorCode::Io, std::string("socket: ") + std::strerror(errno));
  const int one = 1;
  setsockopt(listener.fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (bind(listener.fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 || listen(listener.fd, 16) != 0)
    throw Error(ErrorCode::Io, "127.0.0.1:" + std::to_string(port) + ": cannot listen: " + std::strerror(errno));
  socklen_t len = sizeof addr;
  getsockname(listener.fd, reinterpret_cast<sockaddr*>(&addr), &len);
  const int bound = ntohs(addr.sin_port);

  const SigintCancel sigint;  // Ctrl-C sets a flag; the loop below sees it within kPollMs
  std::printf("serving on http://127.0.0.1:%d/ (Ctrl-C stops)\n", bound);
  std::fflush(stdout);
  while (!SigintCancel::requested()) {
    pollfd pfd{listener.fd, POLLIN, 0};
    const int ready = poll(&pfd, 1, kPollMs);
    if (ready <= 0) continue;  // timeout, or EINTR from SIGINT
    Socket client(accept4(listener.fd, nullptr, nullptr, SOCK_CLOEXEC));
    if (client.fd < 0) continue;
    const timeval timeout{kClientTimeoutSeconds, 0};
    setsockopt(client.fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    setsockopt(client.fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
    answer(client.fd, page, bound);
  }
  std::printf("stopped\n");
}

}  // namespace sogmm::tools
