// Who may reach the console and act: where it listens, and the token an action carries.

#include <sys/stat.h>

#include <charconv>
#include <fstream>

#include "projbot/console/console.hpp"

namespace projbot::console {

ConsoleConfig parse_listen(const std::string& listen, const std::string& what) {
  ConsoleConfig c;
  const std::size_t colon = listen.rfind(':');
  std::string port = listen;
  if (colon != std::string::npos) {
    c.host = listen.substr(0, colon);
    port = listen.substr(colon + 1);
    if (c.host.size() > 2 && c.host.front() == '[' && c.host.back() == ']') c.host = c.host.substr(1, c.host.size() - 2);
    if (c.host.empty()) throw ConsoleError(what + " '" + listen + "': the address before ':' is empty");
  }
  const char* end = port.data() + port.size();
  const auto [ptr, ec] = std::from_chars(port.data(), end, c.port);
  if (port.empty() || ec != std::errc{} || ptr != end || c.port < 0 || c.port > 65535)
    throw ConsoleError(what + " '" + listen + "': expected [ADDR:]PORT with a port from 0 to 65535");
  return c;
}

std::string read_token(const std::filesystem::path& file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) throw ConsoleError(file.string() + ": the console's token file does not exist");
  if (!S_ISREG(st.st_mode)) throw ConsoleError(file.string() + ": the console's token file is not a regular file");
  if ((st.st_mode & (S_IRWXG | S_IRWXO)) != 0)
    throw ConsoleError(file.string() + ": the console's token file is readable or writable by others (chmod 600 it)");
  std::ifstream in(file);
  std::string token;
  std::getline(in, token);
  const auto blank = [](char ch) { return ch == ' ' || ch == '\t' || ch == '\r'; };
  while (!token.empty() && blank(token.back())) token.pop_back();
  while (!token.empty() && blank(token.front())) token.erase(token.begin());
  if (!in && !in.eof()) throw ConsoleError(file.string() + ": the console's token file cannot be read");
  if (token.size() < 16)
    throw ConsoleError(file.string() + ": the console's token must be at least 16 characters on its first line");
  return token;
}

bool is_loopback(const std::string& host) { return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0; }

}  // namespace projbot::console
