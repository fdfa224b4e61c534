// libFuzzer harness of the tracks.csv reader (read_tracks_csv, `omnivert calibrate --tracks`).

#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "fuzz_support.hpp"
#include "omnivert/match/tracks_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = omnivert::fuzz::scratch() / "tracks.csv";
  omnivert::fuzz::write_file(path, omnivert::fuzz::as_text(data, size));
  omnivert::fuzz::expect_input_error_or_success([&] {
    for (const omnivert::TrackRow& r : omnivert::read_tracks_csv(path)) {
      if (r.frame < 0 || r.track_id < 0 || !std::isfinite(r.bearing)) std::abort();
    }
  });
  return 0;
}
