#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include "recording/bytes.hpp"

namespace omnivert::recording {

void decompress_bz2(std::span<const std::uint8_t> in,
                    std::size_t size,
                    std::vector<std::uint8_t>& out,
                    const std::string& what) {
  out.resize(size);
  unsigned int n = static_cast<unsigned int>(size);
  const int rc =
      BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(out.data()),
                                 &n,
                                 const_cast<char*>(reinterpret_cast<const char*>(in.data())),
                                 static_cast<unsigned int>(in.size()),
                                 0,
                                 0);
  if (rc != BZ_OK || n != size) {
    throw InputError(what + ": the bz2 data do not decompress (bzip2 error " + std::to_string(rc) +
                     ", " + std::to_string(n) + " of " + std::to_string(size) + " bytes)");
  }
}

void decompress_lz4_frame(std::span<const std::uint8_t> in,
                          std::size_t size,
                          std::vector<std::uint8_t>& out,
                          const std::string& what) {
  out.resize(size);
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) {
    throw std::runtime_error("lz4: cannot create a decompression context");
  }
  std::size_t done_in = 0, done_out = 0;
  std::size_t rc = 1;
  while (rc != 0 && done_in < in.size()) {
    std::size_t n_out = size - done_out, n_in = in.size() - done_in;
    rc = LZ4F_decompress(ctx, out.data() + done_out, &n_out, in.data() + done_in, &n_in, nullptr);
    if (LZ4F_isError(rc)) break;
    done_in += n_in;
    done_out += n_out;
    if (n_in == 0 && n_out == 0) break;
  }
  LZ4F_freeDecompressionContext(ctx);
  if (LZ4F_isError(rc) || done_out != size) {
    throw InputError(what + ": the lz4 data do not decompress (" +
                     (LZ4F_isError(rc)
                          ? std::string(LZ4F_getErrorName(rc))
                          : std::to_string(done_out) + " of " + std::to_string(size) + " bytes") +
                     ")");
  }
}

void decompress_zstd(std::span<const std::uint8_t> in,
                     std::size_t size,
                     std::vector<std::uint8_t>& out,
                     const std::string& what) {
  if (size == 0) {
    const unsigned long long n = ZSTD_getFrameContentSize(in.data(), in.size());
    if (n == ZSTD_CONTENTSIZE_ERROR || n == ZSTD_CONTENTSIZE_UNKNOWN) {
      throw InputError(what + ": the zstd data do not record their size");
    }
    size = static_cast<std::size_t>(n);
  }
  out.resize(size);
  const std::size_t rc = ZSTD_decompress(out.data(), size, in.data(), in.size());
  if (ZSTD_isError(rc) || rc != size) {
    throw InputError(what + ": the zstd data do not decompress (" +
                     (ZSTD_isError(rc)
                          ? std::string(ZSTD_getErrorName(rc))
                          : std::to_string(rc) + " of " + std::to_string(size) + " bytes") +
                     ")");
  }
}

}  // namespace omnivert::recording
