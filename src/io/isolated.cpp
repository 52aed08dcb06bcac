#include "io/isolated.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <new>
#include <sstream>

#include "io/io_util.h"
#include "lacuna/error.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define LACUNA_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
#define LACUNA_SANITIZED 1
#endif
#endif

namespace lacuna::io {

namespace {

// Writes all of [data, data+n), retrying on EINTR; false if the pipe is gone.
bool write_all(int fd, const void* data, size_t n) {
    const auto* p = static_cast<const char*>(data);
    while (n > 0) {
        const ssize_t w = ::write(fd, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        p += w;
        n -= size_t(w);
    }
    return true;
}

bool read_all(int fd, void* data, size_t n) {
    auto* p = static_cast<char*>(data);
    while (n > 0) {
        const ssize_t r = ::read(fd, p, n);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return false;
        p += r;
        n -= size_t(r);
    }
    return true;
}

uint64_t address_space_now() {
    std::ifstream in("/proc/self/statm");
    uint64_t pages = 0;
    in >> pages;
    return pages * uint64_t(::sysconf(_SC_PAGE_SIZE));
}

std::string signal_text(int sig) {
    const char* name = ::strsignal(sig);
    return "signal " + std::to_string(sig) + (name ? std::string(", ") + name : std::string());
}

}  // namespace

// Message framing on the pipe: tag (1 byte), length (uint32, native), payload.
void ChildChannel::send(char tag, const void* data, size_t n) {
    const uint32_t len = uint32_t(std::min<size_t>(n, UINT32_MAX));
    write_all(m_fd, &tag, 1);
    write_all(m_fd, &len, sizeof len);
    write_all(m_fd, data, len);
}

void ChildChannel::limit_memory(uint64_t extra) {
#ifndef LACUNA_SANITIZED
    rlimit r{};
    ::getrlimit(RLIMIT_AS, &r);
    r.rlim_cur = rlim_t(std::min<uint64_t>(sat_add(address_space_now(), extra), r.rlim_max));
    ::setrlimit(RLIMIT_AS, &r);
#else
    (void)extra;
#endif
}

void run_isolated(const std::string& where, const std::string& field, const std::string& who,
                  const std::function<void(ChildChannel&)>& body,
                  const std::function<void(char, const std::string&)>& on_message,
                  const std::function<void(double)>& progress) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0)
        throw Error(where, field, std::string("cannot start the reader: ") + std::strerror(errno));
    std::fflush(nullptr);  // nothing buffered may be written twice
    const pid_t pid = ::fork();
    if (pid < 0) {
        const int e = errno;
        ::close(fds[0]);
        ::close(fds[1]);
        throw Error(where, field, std::string("cannot start the reader: ") + std::strerror(e));
    }
    if (pid == 0) {
        ::close(fds[0]);
        // Fatal signals kill the child, whatever handlers the parent installed (libFuzzer's
        // would turn GDCM's abort into an ordinary exit): a death is then always a signal.
        // Sanitizer reports (ASan, UBSan) still end the child with their own exit code.
        for (int sig : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL}) ::signal(sig, SIG_DFL);
        // LACUNA_CHILD_STDERR=1 keeps stderr (to read a sanitizer's report from the child).
        if (!std::getenv("LACUNA_CHILD_STDERR")) {
            const int null = ::open("/dev/null", O_RDWR);
            if (null >= 0) {
                ::dup2(null, 1);
                ::dup2(null, 2);
            }
            static std::ostringstream sink;
            std::cerr.rdbuf(sink.rdbuf());
            std::cout.rdbuf(sink.rdbuf());
        }
        ChildChannel ch(fds[1]);
        int rc = 0;
        try {
            body(ch);
        } catch (const Error& e) {
            ch.send('E', e.what());
        } catch (const std::bad_alloc&) {
            ch.send('E', where + ": memory: out of memory while reading (a damaged length?)");
        } catch (const std::exception& e) {
            ch.send('E', where + ": " + field + ": " + one_line(e.what()));
        } catch (...) {
            rc = 1;
        }
        ::_exit(rc);
    }
    ::close(fds[1]);

    // Parent: collect messages until the child closes the pipe, then reap it. If anything here
    // throws (a progress callback cancelling), the child is killed and reaped first.
    std::string error, file;
    bool have_error = false;
    auto reap = [&](bool kill_it) {
        if (kill_it) ::kill(pid, SIGKILL);
        int status = 0;
        while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
        return status;
    };
    try {
        for (;;) {
            char tag = 0;
            uint32_t len = 0;
            if (!read_all(fds[0], &tag, 1) || !read_all(fds[0], &len, sizeof len)) break;
            std::string payload(len, '\0');
            if (len && !read_all(fds[0], payload.data(), len)) break;
            if (tag == 'F') {
                file = payload;
            } else if (tag == 'P') {
                double f = 0;
                if (payload.size() == sizeof f) std::memcpy(&f, payload.data(), sizeof f);
                report(progress, f);
            } else if (tag == 'E') {
                error = payload;
                have_error = true;
            } else {
                on_message(tag, payload);
            }
        }
    } catch (...) {
        ::close(fds[0]);
        reap(true);
        throw;
    }
    ::close(fds[0]);
    const int status = reap(false);
    if (have_error) throw Error(error);
    const std::string on =
        file.empty() ? "" : " on " + std::filesystem::path(file).filename().string();
    if (WIFSIGNALED(status))
        throw Error(where, field,
                    who + " died (" + signal_text(WTERMSIG(status)) + ")" + on +
                        (field == "output" ? ": cannot write (disk full or file size limit?)"
                                           : ": the file is damaged or not supported"));
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw Error(where, field, who + " failed" + on);
}

}  // namespace lacuna::io
