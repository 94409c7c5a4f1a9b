// Appends observables to an H5MD file forever, flushing after each record,
// and prints the number of records written after each flush. The kill test
// (test_recorder_kill.sh) SIGKILLs it and checks the file.
//
// Usage: h5md_kill_writer FILE.h5
#include <chrono>
#include <cstdio>
#include <thread>

#include "dynhet/h5md.hpp"

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: h5md_kill_writer FILE.h5\n");
    return 2;
  }
  dynhet::H5mdWriter w(argv[1], "h5md_kill_writer", "0");
  w.write_parameters("[system]\nn_particles = 3\n");
  w.set_particles("all", 10.0, std::vector<int32_t>{0, 1, 0});
  for (int64_t i = 0;; ++i) {
    // Record i: step i, time i / 2, vector value (i, 2i, 3i), scalar i.
    const double v[3] = {1.0 * i, 2.0 * i, 3.0 * i};
    const int32_t k = static_cast<int32_t>(i);
    w.append_observable("vector", i, 0.5 * i, v, 3);
    w.append_observable("scalar", i, 0.5 * i, &k, 1);
    if (i % 10 == 0) w.append_frame(i, 0.5 * i, {0.5 * i, -1, 11, 2, 3, 30});
    std::printf("%lld\n", static_cast<long long>(i + 1));
    std::fflush(stdout);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}
