#include "movie.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "io/io_util.h"
#include "lacuna/error.h"

extern char** environ;

namespace lacuna::cli {

namespace fs = std::filesystem;
using namespace io;  // temp names, fsync, rename (src/io/io_util.h)

std::string find_ffmpeg() {
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path ? path : "");
    for (std::string dir; std::getline(dirs, dir, ':');) {
        if (dir.empty()) continue;
        const std::string f = dir + "/ffmpeg";
        if (::access(f.c_str(), X_OK) == 0 && !fs::is_directory(f)) return f;
    }
    return "";
}

void require_ffmpeg() {
    if (find_ffmpeg().empty())
        throw Error("--movie", "ffmpeg",
                    "no ffmpeg program on PATH; install the Debian package ffmpeg "
                    "(scripts/install-deps)");
}

MovieWriter::MovieWriter(std::string path, int width, int height, int fps)
    : m_path(std::move(path)), m_width(width), m_height(height) {
    const std::string ffmpeg = find_ffmpeg();
    if (ffmpeg.empty()) require_ffmpeg();
    const TempName tmp = temp_name_beside(m_path);
    remove_stale_temp_files(tmp.dir);
    m_tmp = tmp.path;
    m_tmp_dir = tmp.dir;
    // ffmpeg's stderr, for the error line: a temporary of its own in the temp folder.
    std::string log = (fs::temp_directory_path() / "lacuna-ffmpeg-XXXXXX").string();
    const int log_fd = ::mkstemp(log.data());
    if (log_fd < 0)
        throw Error(m_path, "movie",
                    std::string("cannot create ffmpeg's log: ") + std::strerror(errno));
    m_log = log;
    int pipe_fd[2];
    if (::pipe2(pipe_fd, O_CLOEXEC) != 0) {
        ::close(log_fd);
        ::unlink(m_log.c_str());
        throw Error(m_path, "movie", std::string("cannot make a pipe: ") + std::strerror(errno));
    }
    // A write to a pipe whose reader died must fail with EPIPE (reported), not kill lacuna.
    ::signal(SIGPIPE, SIG_IGN);
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    const std::vector<std::string> args = {
        ffmpeg, "-nostdin", "-hide_banner", "-loglevel", "error", "-y",
        // the input: raw RGBA frames on stdin, top row first (lacuna::Image)
        "-f", "rawvideo", "-pix_fmt", "rgba", "-s", size, "-framerate", std::to_string(fps), "-i",
        "pipe:0",
        // H.264 needs even edges in yuv420p: pad an odd one with a black row or column
        "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p",
        "-movflags", "+faststart", "-f", "mp4", m_tmp};
    std::vector<char*> argv;
    for (const std::string& s : args) argv.push_back(const_cast<char*>(s.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, pipe_fd[0], 0);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_adddup2(&fa, log_fd, 2);
    const int rc = ::posix_spawn(&m_pid, ffmpeg.c_str(), &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    ::close(pipe_fd[0]);
    ::close(log_fd);
    m_fd = pipe_fd[1];
    if (rc != 0) {
        m_pid = -1;
        fail(std::string("cannot start ") + ffmpeg + ": " + std::strerror(rc));
    }
}

int MovieWriter::wait_status() {
    int status = 0;
    while (::waitpid(m_pid, &status, 0) < 0 && errno == EINTR) {
    }
    m_pid = -1;
    return status;
}

// Stops ffmpeg (if it still runs), removes the temporary and throws one line: `what` and the
// last line ffmpeg wrote on its stderr.
void MovieWriter::fail(const std::string& what) {
    if (m_fd >= 0) ::close(m_fd), m_fd = -1;
    if (m_pid > 0) {
        ::kill(m_pid, SIGTERM);
        wait_status();
    }
    std::string last;
    {
        std::ifstream f(m_log);
        for (std::string line; std::getline(f, line);)
            if (!trim(line).empty()) last = trim(line);
    }
    ::unlink(m_log.c_str());
    ::unlink(m_tmp.c_str());
    m_log.clear();
    m_tmp.clear();
    throw Error(m_path, "movie", one_line(what + (last.empty() ? "" : ": ffmpeg says: " + last)));
}

void MovieWriter::add(const Image& frame) {
    if (frame.width != m_width || frame.height != m_height)
        fail("frame " + std::to_string(m_frames) + " is " + std::to_string(frame.width) + "x" +
             std::to_string(frame.height) + ", the movie " + std::to_string(m_width) + "x" +
             std::to_string(m_height));
    const uint8_t* p = frame.rgba.data();
    size_t left = frame.rgba.size();
    while (left > 0) {
        const ssize_t n = ::write(m_fd, p, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            // The reader is gone: ffmpeg stopped; its status and message say why.
            const int err = errno;
            ::close(m_fd), m_fd = -1;
            const int status = wait_status();
            fail("ffmpeg stopped reading at frame " + std::to_string(m_frames) +
                 (WIFEXITED(status) ? " (exit " + std::to_string(WEXITSTATUS(status)) + ")"
                                    : " (signal " + std::to_string(WTERMSIG(status)) + ")") +
                 (err == EPIPE ? "" : std::string(", ") + std::strerror(err)));
        }
        p += n;
        left -= size_t(n);
    }
    ++m_frames;
}

void MovieWriter::finish() {
    ::close(m_fd), m_fd = -1;
    const int status = wait_status();
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        fail(WIFEXITED(status) ? "ffmpeg failed (exit " + std::to_string(WEXITSTATUS(status)) + ")"
                               : "ffmpeg died (signal " + std::to_string(WTERMSIG(status)) + ")");
    std::error_code ec;
    if (fs::file_size(m_tmp, ec) == 0 || ec) fail("ffmpeg wrote no movie");
    try {
        sync_file(m_tmp, m_path);
        rename_over(m_tmp, m_path);
    } catch (const Error& e) {
        fail(e.what());
    }
    sync_dir(m_tmp_dir);
    ::unlink(m_log.c_str());
    m_log.clear();
    m_tmp.clear();
}

MovieWriter::~MovieWriter() {
    if (m_fd >= 0) ::close(m_fd);
    if (m_pid > 0) {
        ::kill(m_pid, SIGTERM);
        int status = 0;
        while (::waitpid(m_pid, &status, 0) < 0 && errno == EINTR) {
        }
    }
    if (!m_tmp.empty()) ::unlink(m_tmp.c_str());
    if (!m_log.empty()) ::unlink(m_log.c_str());
}

}  // namespace lacuna::cli
