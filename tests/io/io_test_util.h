// Helpers for the io tests: scratch directories, file bytes, small synthetic volumes.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "lacuna/error.h"
#include "lacuna/volume.h"

namespace lacuna::test {

namespace fs = std::filesystem;

// A fresh directory under the system temp dir, removed with everything in it.
class ScratchDir {
  public:
    ScratchDir() {
        static std::atomic<int> counter{0};
        m_path = fs::temp_directory_path() /
                 ("lacuna-io-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
        fs::remove_all(m_path);
        fs::create_directories(m_path);
    }
    ~ScratchDir() {
        std::error_code ec;
        fs::permissions(m_path, fs::perms::owner_all, fs::perm_options::add, ec);
        fs::remove_all(m_path, ec);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    std::string file(const std::string& name) const { return (m_path / name).string(); }
    const fs::path& path() const { return m_path; }
    std::vector<std::string> names() const {
        std::vector<std::string> out;
        for (const auto& e : fs::directory_iterator(m_path)) out.push_back(e.path().filename());
        std::sort(out.begin(), out.end());
        return out;
    }

  private:
    fs::path m_path;
};

inline std::vector<uint8_t> file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

inline void write_bytes(const std::string& path, const void* data, size_t n) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(static_cast<const char*>(data), std::streamsize(n));
}
inline void write_bytes(const std::string& path, const std::vector<uint8_t>& b) {
    write_bytes(path, b.data(), b.size());
}
inline void write_text(const std::string& path, const std::string& text) {
    write_bytes(path, text.data(), text.size());
}

// A volume with a recognisable pattern and full-range values, plus non-trivial geometry.
inline Volume pattern_volume(Vec3i dims, VoxelType type, uint32_t seed = 7) {
    Volume v(dims, type, "pattern");
    std::mt19937 rng(seed);
    const size_t n = v.voxel_count();
    switch (type) {
        case VoxelType::UInt8:
            for (size_t i = 0; i < n; ++i) v.data_as<uint8_t>()[i] = uint8_t(rng());
            break;
        case VoxelType::Int16:
            for (size_t i = 0; i < n; ++i) v.data_as<int16_t>()[i] = int16_t(rng());
            break;
        case VoxelType::UInt16:
            for (size_t i = 0; i < n; ++i) v.data_as<uint16_t>()[i] = uint16_t(rng());
            break;
        case VoxelType::Float32:
            for (size_t i = 0; i < n; ++i) v.data_as<float>()[i] = float(int32_t(rng())) / 65536.f;
            break;
    }
    v.spacing = {0.5, 0.75, 1.25};
    v.origin = {-10.0, 20.0, 3.5};
    v.compute_range("pattern");
    return v;
}

inline bool same_voxels(const Volume& a, const Volume& b) {
    return a.dims() == b.dims() && a.type() == b.type() &&
           std::memcmp(a.data(), b.data(), a.bytes()) == 0;
}

// Runs f, expects lacuna::Error, and returns its message.
// Runs check() with the permissions of an ordinary user, so that tests of unwritable folders
// mean something when the suite runs as root (root ignores permission bits): as root, check()
// runs in a forked child that first drops to uid/gid 65534 ("nobody"). Returns check()'s result.
// check() must not use gtest assertions (they would not reach the parent).
inline bool as_unprivileged(const std::function<bool()>& check) {
    if (::geteuid() != 0) return check();
    const pid_t pid = ::fork();
    if (pid == 0) {
        if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(3);
        bool ok = false;
        try {
            ok = check();
        } catch (...) {
        }
        ::_exit(ok ? 0 : 1);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// The message of the lacuna::Error f throws, or "" (no assertions: usable in as_unprivileged).
inline std::string quiet_error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    } catch (...) {
    }
    return "";
}

inline std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected lacuna::Error, got another exception: " << e.what();
        return "";
    }
    ADD_FAILURE() << "expected lacuna::Error, nothing was thrown";
    return "";
}

}  // namespace lacuna::test
