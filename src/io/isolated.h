// Running a library that may abort in a child process, so its failures become errors.
//
// GDCM (through ITK's GDCMImageIO) asserts on some damaged files (`gdcmFileMetaInformation.cxx:
// Assertion '0 && "Should not happen"'`) and allocates whatever a damaged length field says. No
// check of ours can promise GDCM never reaches such a state, so GDCM runs in a forked child:
//   - whatever the child throws comes back as the same lacuna::Error line;
//   - a child that dies of a signal (an abort, a segfault, the kernel's OOM killer) becomes
//     Error(where, field, "<who> died (signal 6, Aborted) on <file>: ...");
//   - the child's address space is capped (RLIMIT_AS, soft limit) to what the caller allows, so
//     a damaged length fails an allocation instead of taking the machine's memory. Sanitizer
//     builds reserve terabytes of shadow memory, so there the cap is not set.
// Bulk results (voxels) travel through a memfd the child fills and the parent maps; messages
// through a pipe. The child never runs the caller's progress callback: it sends fractions that
// the parent reports. The child writes nothing to the terminal (stdout/stderr go to /dev/null)
// and leaves with _exit, so no destructor or atexit handler of the parent's state runs twice.
#pragma once
#include <cstdint>
#include <functional>
#include <string>

namespace lacuna::io {

class ChildChannel {
  public:
    explicit ChildChannel(int fd) : m_fd(fd) {}
    void send(char tag, const void* data, size_t n);
    void send(char tag, const std::string& s) { send(tag, s.data(), s.size()); }
    // Names the file being worked on, for the message if the child dies.
    void working_on(const std::string& file) { send('F', file); }
    void progress(double f) { send('P', &f, sizeof f); }
    // Caps the child's address space at its current size plus `extra` bytes (soft RLIMIT_AS;
    // may be raised again later). No-op in sanitizer builds.
    void limit_memory(uint64_t extra);

  private:
    int m_fd;
};

// Runs body(channel) in a forked child and waits for it. on_message(tag, payload) runs in the
// parent for every message the body sent (tags other than 'F', 'P' and the internal 'E').
// Throws the child's lacuna::Error, or Error(where, field, "<who> died ...") when it died.
void run_isolated(const std::string& where, const std::string& field, const std::string& who,
                  const std::function<void(ChildChannel&)>& body,
                  const std::function<void(char, const std::string&)>& on_message,
                  const std::function<void(double)>& progress);

}  // namespace lacuna::io
