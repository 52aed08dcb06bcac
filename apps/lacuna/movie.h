// `lacuna render --movie out.mp4`: frames to an H.264 MP4 through the ffmpeg program (Debian's
// `ffmpeg` package, installed by scripts/install-deps).
//
// Why the program and not libavcodec: the frames are already RGBA in memory, and ffmpeg reads
// raw RGBA on a pipe (`-f rawvideo -pix_fmt rgba`), so the whole encoder is one argument list;
// linking libavcodec would add a dozen -dev packages for the same bytes.
//
// Why nothing half-written (invariant 3): ffmpeg writes a temporary file beside the target
// (io_util's temp_name_beside, ".tmp-<pid>-<n>-out.mp4"); only when it exits with status 0 and
// the file is non-empty is it fsync'ed and renamed over the target. Any failure (ffmpeg missing,
// killed, refusing the input, a full disk, an exception in the render loop) removes the
// temporary and leaves the target as it was. ffmpeg's own stderr goes to a temporary file whose
// last line becomes part of our one-line error, so the error stays one line.
//
// Sizes: H.264 in yuv420p needs even width and height; an odd edge is padded with one black
// row or column (ffmpeg's pad filter), so a 65x64 render makes a 66x64 movie.
#pragma once
#include <sys/types.h>

#include <string>

#include "lacuna/image.h"

namespace lacuna::cli {

// The ffmpeg on PATH, or "" when there is none.
std::string find_ffmpeg();
// Throws lacuna::Error("--movie", "ffmpeg", ...) naming the package when find_ffmpeg() is "".
void require_ffmpeg();

class MovieWriter {
  public:
    // Starts ffmpeg encoding width x height RGBA frames at `fps` into a temporary beside `path`.
    MovieWriter(std::string path, int width, int height, int fps);
    // Sends one frame (its size must be the movie's). Throws lacuna::Error if ffmpeg has gone.
    void add(const Image& frame);
    // Ends the stream, waits for ffmpeg, checks its status and renames the file into place.
    void finish();
    // Without finish(): stops ffmpeg and removes the temporary (the target is untouched).
    ~MovieWriter();
    MovieWriter(const MovieWriter&) = delete;
    MovieWriter& operator=(const MovieWriter&) = delete;
    int frames() const { return m_frames; }

  private:
    [[noreturn]] void fail(const std::string& what);
    int wait_status();
    std::string m_path, m_tmp, m_tmp_dir, m_log;
    int m_width, m_height;
    int m_fd = -1;  // the pipe to ffmpeg's stdin
    pid_t m_pid = -1;
    int m_frames = 0;
};

}  // namespace lacuna::cli
