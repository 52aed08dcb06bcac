// The launcher the MPI tests start, with what this machine needs: more ranks than cores, root in
// containers.
//
// In the sanitizer suite (scripts/sanitize) the ranks run with leak detection off: Open MPI
// 4.1.4 leaks in MPI_Init from components it dlcloses at MPI_Finalize, and its frames have no
// frame pointers, so LeakSanitizer sees one-frame stacks in `<unknown module>` that no
// suppression can name (google/sanitizers#615, open-mpi/ompi#12584). scripts/sanitize exports
// LACUNA_MPI_RANK_LSAN_OPTIONS (its LSAN_OPTIONS plus detect_leaks=0) and the ranks get it as
// their LSAN_OPTIONS; they still run under ASan and UBSan, and the distributed code's own leaks
// are checked in-process by lacuna_tests (DistributedFrame, Composite, BrickRead).
#pragma once
#include <unistd.h>

#include <cstdlib>
#include <string>

// The launcher alone (what `lacuna bench mpi --mpirun` takes; it adds the flags itself).
inline std::string mpirun_launcher() {
    std::string cmd;
    if (const char* lsan = std::getenv("LACUNA_MPI_RANK_LSAN_OPTIONS"))
        cmd = std::string("env \"LSAN_OPTIONS=") + lsan + "\" ";
    return cmd + LACUNA_MPIEXEC;
}
// The launcher with the flags this machine needs.
inline std::string mpirun_command() {
    return mpirun_launcher() + (::geteuid() == 0 ? " --allow-run-as-root" : "") +
           " --oversubscribe";
}
