// ITK plumbing shared by the ITK-based readers and writers. Only src/io/ includes ITK.
#pragma once
#include <itkCommonEnums.h>

#include <cstdio>
#include <exception>
#include <mutex>
#include <sstream>
#include <string>

#include "io/io_util.h"

namespace lacuna::io {

// Registers the ImageIO factories lacuna links (NIfTI, NRRD, MetaImage, GDCM) and silences
// ITK's warning window. Idempotent and thread-safe; every ITK entry point calls it first.
void init_itk();

// The one-line description of an exception thrown by ITK (or anything else): ITK's what()
// carries "file:line:\nitk::ERROR: Class(0x...): description"; only the description is kept,
// and of NrrdIO's error stack only the innermost entry.
std::string itk_message(const std::exception& e);

// Maps an ITK component type to ours; throws Error(where, "voxel type", ...) for the rest.
DiskType disk_type_from_itk(itk::IOComponentEnum c, const std::string& where);
itk::IOComponentEnum itk_component_of(VoxelType t);

// While alive, std::cerr goes to a buffer and file descriptor 2 to a temporary file instead of
// the terminal: MetaIO and GDCM print diagnostics to std::cerr on their own, niftilib to C's
// stderr. Holds a process-wide lock, so concurrent ITK calls serialise
// (they are I/O bound anyway); another thread printing to std::cerr meanwhile is swallowed.
// Never call user code (progress callbacks) while one is alive. text() returns what was
// printed, on one line.
class QuietStderr {
  public:
    QuietStderr();
    ~QuietStderr();
    QuietStderr(const QuietStderr&) = delete;
    QuietStderr& operator=(const QuietStderr&) = delete;
    std::string text() const;

  private:
    std::unique_lock<std::mutex> m_lock;
    std::ostringstream m_buffer;
    std::streambuf* m_saved = nullptr;
    std::FILE* m_file = nullptr;  // what C code wrote to file descriptor 2 meanwhile
    int m_saved_fd = -1;
};

}  // namespace lacuna::io
