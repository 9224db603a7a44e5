// What ModbusClient says about a response that is not an exception (issue 24): a server on
// 127.0.0.1 answers a read with the wrong transaction id; the client names a framing /
// transaction-id mismatch and no Modbus exception, and a real exception still names its number.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <thread>

#include <gtest/gtest.h>

#include "devices/modbus_client.hpp"
#include "tests/loopback_listener.hpp"

namespace bellows {
namespace {

/// Accepts one connection and answers its first request with `reply(request)` (MBAP + PDU bytes).
class OneShotServer {
 public:
  template <typename Reply>
  explicit OneShotServer(Reply reply) {
    sockaddr_in address{};
    listen_fd_ = testing::loopback_listener(address);
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this, reply] {
      const int fd = ::accept(listen_fd_, nullptr, nullptr);
      if (fd < 0) return;
      std::uint8_t request[260];
      const ssize_t got = ::read(fd, request, sizeof request);
      if (got >= 8) {
        const std::vector<std::uint8_t> answer = reply(request);
        [[maybe_unused]] const ssize_t sent = ::write(fd, answer.data(), answer.size());
      }
      std::uint8_t rest[16];
      while (::read(fd, rest, sizeof rest) > 0) {
      }
      ::close(fd);
    });
  }
  ~OneShotServer() {
    ::shutdown(listen_fd_, SHUT_RDWR);
    thread_.join();
    ::close(listen_fd_);
  }
  int port() const { return port_; }

 private:
  int listen_fd_ = -1;
  int port_ = 0;
  std::thread thread_;
};

/// A register read's answer (function 3, one register) with transaction id `tid`.
std::vector<std::uint8_t> read_answer(std::uint16_t tid, const std::uint8_t* request) {
  return {static_cast<std::uint8_t>(tid >> 8), static_cast<std::uint8_t>(tid), 0, 0, 0, 5, request[6], 3, 2, 0, 42};
}

TEST(ModbusClientErrors, AWrongTransactionIdIsAMismatchNotAnException) {
  OneShotServer server([](const std::uint8_t* request) {
    const auto tid = static_cast<std::uint16_t>((request[0] << 8 | request[1]) + 7);  // not the request's
    return read_answer(tid, request);
  });
  ModbusClient client("127.0.0.1", server.port());
  ASSERT_EQ(client.connect(2.0), "");
  client.set_response_timeout(2.0);
  std::uint16_t value = 0;
  EXPECT_FALSE(client.read(0, 1, &value));
  EXPECT_EQ(client.last_error().find("Modbus exception"), std::string::npos) << client.last_error();
  EXPECT_NE(client.last_error().find("transaction-id mismatch"), std::string::npos) << client.last_error();
  EXPECT_NE(client.last_error().find("sent no exception"), std::string::npos) << client.last_error();
}

TEST(ModbusClientErrors, AnExceptionTheDeviceSentNamesItsNumber) {
  OneShotServer server([](const std::uint8_t* request) {
    return std::vector<std::uint8_t>{request[0], request[1], 0, 0, 0, 3, request[6], 0x83, 2};  // illegal data address
  });
  ModbusClient client("127.0.0.1", server.port());
  ASSERT_EQ(client.connect(2.0), "");
  client.set_response_timeout(2.0);
  std::uint16_t value = 0;
  EXPECT_FALSE(client.read(0, 1, &value));
  EXPECT_NE(client.last_error().find("(Modbus exception 2)"), std::string::npos) << client.last_error();
}

// A reconnect (after a lost connection, inside an exchange's 4 ms deadline) looks up no name: a
// lookup waits on a name server, and the vent waits behind that exchange.
TEST(ModbusClientConnect, AReconnectReusesTheAddressesTheFirstConnectResolved) {
  sockaddr_in address{};
  const int listener = testing::loopback_listener(address);
  // A numeric address (getaddrinfo all the same): a test sends nothing to a name server.
  ModbusClient client("127.0.0.1", ntohs(address.sin_port));
  ASSERT_EQ(client.connect(2.0), "");
  const int first = ::accept(listener, nullptr, nullptr);
  ASSERT_EQ(client.connect(2.0), "") << "the same listener, reached again";
  const int second = ::accept(listener, nullptr, nullptr);
  EXPECT_EQ(client.reconnects(), 1u);
  EXPECT_EQ(client.address_resolutions(), 1u);
  ::close(first);
  ::close(second);
  ::close(listener);
}

}  // namespace
}  // namespace bellows
