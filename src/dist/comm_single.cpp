// The one-process stand-in for MPI (src/dist/comm.h), built when CMake finds no MPI: one rank,
// nothing to send, never launched.
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "dist/comm.h"

namespace lacuna::dist {

bool launched() {
    return false;
}
int launcher_rank() {
    return 0;
}

Comm::Comm() = default;

Comm& Comm::world() {
    static Comm c;
    return c;
}

void Comm::barrier() {}
// One rank has no peer: a message to one is a bug of the caller.
void Comm::send(int, int, const void*, size_t) {
    throw std::logic_error("dist::Comm::send: one rank");
}
void Comm::recv(int, int, void*, size_t) {
    throw std::logic_error("dist::Comm::recv: one rank");
}
void Comm::sendrecv(int, int, const void*, size_t, void*, size_t) {
    throw std::logic_error("dist::Comm::sendrecv: one rank");
}
void Comm::exchange(int, const std::vector<Transfer>& transfers) {
    if (!transfers.empty()) throw std::logic_error("dist::Comm::exchange: one rank");
}
std::vector<uint8_t> Comm::gather(const void* mine, size_t bytes) {
    const auto* p = static_cast<const uint8_t*>(mine);
    return std::vector<uint8_t>(p, p + bytes);
}
void Comm::sum_to_root(std::vector<uint32_t>&) {}
void Comm::minmax(float&, float&) {}
uint64_t Comm::sum(uint64_t v) {
    return v;
}
std::vector<uint8_t> Comm::allgather(const void* mine, size_t bytes) {
    return gather(mine, bytes);
}
void Comm::post(int, const std::vector<uint8_t>&) {
    throw std::logic_error("dist::Comm::post: one rank");
}
std::vector<uint8_t> Comm::await(int) {
    throw std::logic_error("dist::Comm::await: one rank");
}
void Comm::abort(int code) {
    std::exit(code);
}

}  // namespace lacuna::dist
