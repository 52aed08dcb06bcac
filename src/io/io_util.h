// Helpers shared by the readers and writers in src/io/ (private to the library).
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "lacuna/io.h"
#include "lacuna/volume.h"

namespace lacuna::io {

// Overflow-safe size arithmetic: sizes come from files and may be anything. Both saturate at
// UINT64_MAX, which no budget or file size reaches, so a saturated result always fails the
// check it feeds.
inline uint64_t sat_add(uint64_t a, uint64_t b) {
    return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}
inline uint64_t sat_mul(uint64_t a, uint64_t b) {
    return b != 0 && a > UINT64_MAX / b ? UINT64_MAX : a * b;
}
// Bytes of a dims.x * dims.y * dims.z grid of `elem`-byte voxels (saturating; dims >= 0).
uint64_t grid_bytes(Vec3i dims, uint64_t elem);
std::string dims_string(Vec3i dims);  // "30000x30000x3"

// The memory check every reader makes from the header, before allocating anything: throws
// Error(where, field, "<what> needs 5.4 GB, more than <budget.name> 12 GB") when `need`
// exceeds the budget. `what` names the allocation, e.g. "30000x30000x3 int16".
void check_budget(const std::string& where, const std::string& field, const std::string& what,
                  uint64_t need, const MemoryBudget& budget);

std::string to_lower(std::string s);

// The format-defining extension of a path, lowercased: ".nii.gz", ".nii", ".nrrd", ".nhdr",
// ".mha", ".mhd", ".raw", ... ("" if the name has no dot).
std::string format_extension(const std::string& path);

// Throws Error(path, "file", ...) unless path names an existing, readable regular file.
void check_readable_file(const std::string& path);
// Throws Error(path, "output", "cannot write: <strerror>") unless path's directory exists and is
// writable (the check is advisory; the real write reports its own failure).
void check_writable_dir(const std::string& path);

// `s` without leading and trailing blanks (spaces, tabs, carriage returns): header fields.
std::string trim(const std::string& s);

// Collapses a (possibly multi-line) library message into one trimmed line of at most
// `max_chars` characters.
std::string one_line(const std::string& text, size_t max_chars = 300);

// A name for a temporary file beside `path` that keeps path's file name, and so its extension:
// "dir/.tmp-<pid>-<n>-name.nii.gz". Companion files a writer derives from it (a detached
// header's data file) share the prefix, so remove_temp_files can find them all.
struct TempName {
    std::string path;    // full temporary path
    std::string prefix;  // ".tmp-<pid>-<n>-" (file-name prefix shared by companion files)
    std::string dir;     // directory ("." when path has none)
};
TempName temp_name_beside(const std::string& path);
// Removes every file in t.dir whose name starts with t.prefix (cleanup after a failed write).
void remove_temp_files(const TempName& t) noexcept;
// Removes temporaries that dead writers left in `dir`: entries named ".tmp-<pid>-<n>-..." whose
// <pid> is not this process and names no live process (kill(pid, 0) fails with ESRCH). A pid
// that was reused by an unrelated live process keeps its debris until that process ends: the
// rule never removes a file a live writer may still be filling. Best effort, never throws.
void remove_stale_temp_files(const std::string& dir) noexcept;
// fsync(2)s a written file before it is renamed into place; throws
// Error(where, "output", "cannot write: fsync: <strerror>").
void sync_file(const std::string& path, const std::string& where);
// fsync(2)s a folder after a rename in it, so the new name survives a crash. Best effort: the
// file is complete and in place already, so a failure here is not reported.
void sync_dir(const std::string& dir) noexcept;
// Throws Error(where, "output", "cannot write: ... has N bytes, expected M (disk full?)")
// unless `path` has exactly `expected` bytes (at least, when `at_least`). Catches writers that
// report a short write only on stderr (ITK's), or not at all.
void expect_file_size(const std::string& path, uint64_t expected, const std::string& where,
                      bool at_least = false);
// Renames `from` over `to`; throws Error(to, "output", ...) on failure.
void rename_over(const std::string& from, const std::string& to);
// Writes `text` to `path` atomically: a temporary file beside it (temp_name_beside), checked,
// fsync'ed, then rename_over. On a failed write the temporary file is removed and
// Error(path, "output", ...) is thrown, so nothing is left half-written.
void write_text_atomic(const std::string& path, const std::string& text);

// Calls progress(f) if set; exceptions from the callback propagate.
inline void report(const std::function<void(double)>& progress, double f) {
    if (progress) progress(f);
}

// Voxel types as they may appear in files. Everything lacuna does not store natively is
// converted on read: int8 -> int16, (u)int32/(u)int64/float64 -> float32.
enum class DiskType : uint8_t { U8, I8, U16, I16, U32, I32, U64, I64, F32, F64 };
size_t disk_type_size(DiskType t);
std::string to_string(DiskType t);
// The lacuna type a disk type is stored as (int8 widens to int16, wide types become float32).
VoxelType stored_type(DiskType t);
// The disk type whose bytes are exactly a lacuna voxel type.
DiskType disk_type_of(VoxelType t);

// Converts `count` voxels of disk type `src` at `in` to v's type, writing voxels
// [first, first + count) of v. Applies value * slope + intercept when `rescale` is set (only
// valid when v is float32). Byte order must already be native.
void convert_voxels(DiskType src, const void* in, size_t count, Volume& v, size_t first,
                    bool rescale = false, double slope = 1.0, double intercept = 0.0);

// Reverses the byte order of `count` elements of `elem_size` bytes in place.
void swap_bytes(void* data, size_t count, size_t elem_size);

// Reads a voxel stream into v. `read(buf, n)` must fill up to n bytes and return how many it
// read (fewer only at end of data); it may throw. Same-type data goes straight into v's
// buffer; other types go through a small staging buffer, never a full-size copy. Throws
// Error(where, "voxel data", "truncated: ...") when the stream ends early.
void read_voxel_stream(const std::function<size_t(void*, size_t)>& read, DiskType disk, bool swap,
                       Volume& v, const std::string& where,
                       const std::function<void(double)>& progress, bool rescale = false,
                       double slope = 1.0, double intercept = 0.0);

inline bool host_is_big_endian() {
    const uint16_t probe = 1;
    return *reinterpret_cast<const uint8_t*>(&probe) == 0;
}

}  // namespace lacuna::io
