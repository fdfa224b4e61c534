#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>

#include "recording/bytes.hpp"

namespace omnivert::recording {

namespace {

// The output buffer grows with what the data actually decompress to, from a first size
// proportional to the input, up to the size the container records: a damaged size field
// (a chunk "of 2^40 bytes") costs nothing until the data back it.
class Growing {
 public:
  Growing(std::vector<std::uint8_t>& out, std::size_t size, std::size_t in_size)
      : out_(out), size_(size) {
    out_.resize(std::min(size, std::max<std::size_t>(1 << 20, 8 * in_size)));
  }
  // Room after `done` bytes: grows the buffer (doubling, at most to the recorded size) when
  // it is full; 0 when the recorded size is reached.
  std::size_t room(std::size_t done) {
    if (done == out_.size() && out_.size() < size_) out_.resize(std::min(size_, 2 * out_.size()));
    return out_.size() - done;
  }
  std::uint8_t* at(std::size_t done) { return out_.data() + done; }

 private:
  std::vector<std::uint8_t>& out_;
  std::size_t size_;
};

}  // namespace

void decompress_bz2(std::span<const std::uint8_t> in,
                    std::size_t size,
                    std::vector<std::uint8_t>& out,
                    const std::string& what) {
  Growing g(out, size, in.size());
  bz_stream s{};
  int rc = BZ2_bzDecompressInit(&s, 0, 0);
  std::size_t done = 0;
  if (rc == BZ_OK) {
    s.next_in = const_cast<char*>(reinterpret_cast<const char*>(in.data()));
    s.avail_in = static_cast<unsigned int>(in.size());
    while (rc == BZ_OK) {
      const std::size_t room = std::min<std::size_t>(g.room(done), 1u << 30);
      if (room == 0) break;
      s.next_out = reinterpret_cast<char*>(g.at(done));
      s.avail_out = static_cast<unsigned int>(room);
      rc = BZ2_bzDecompress(&s);
      const std::size_t produced = room - s.avail_out;
      done += produced;
      if (rc == BZ_OK && produced == 0 && s.avail_in == 0) break;  // input ends early
    }
    BZ2_bzDecompressEnd(&s);
  }
  if (rc != BZ_STREAM_END || done != size) {
    throw InputError(what + ": the bz2 data do not decompress (bzip2 error " + std::to_string(rc) +
                     ", " + std::to_string(done) + " of " + std::to_string(size) + " bytes)");
  }
  out.resize(size);
}

void decompress_lz4_frame(std::span<const std::uint8_t> in,
                          std::size_t size,
                          std::vector<std::uint8_t>& out,
                          const std::string& what) {
  Growing g(out, size, in.size());
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) {
    throw std::runtime_error("lz4: cannot create a decompression context");
  }
  std::size_t done_in = 0, done_out = 0;
  std::size_t rc = 1;
  while (rc != 0 && done_in < in.size()) {
    std::size_t n_out = g.room(done_out), n_in = in.size() - done_in;
    rc = LZ4F_decompress(ctx, g.at(done_out), &n_out, in.data() + done_in, &n_in, nullptr);
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
  out.resize(size);
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
  Growing g(out, size, in.size());
  ZSTD_DCtx* ctx = ZSTD_createDCtx();
  if (!ctx) throw std::runtime_error("zstd: cannot create a decompression context");
  ZSTD_inBuffer src{in.data(), in.size(), 0};
  std::size_t done = 0, rc = 1;
  while (rc != 0) {
    const std::size_t room = g.room(done);
    if (room == 0) break;
    ZSTD_outBuffer dst{g.at(done), room, 0};
    rc = ZSTD_decompressStream(ctx, &dst, &src);
    done += dst.pos;
    if (ZSTD_isError(rc) || (dst.pos == 0 && src.pos == src.size)) break;
  }
  ZSTD_freeDCtx(ctx);
  if (ZSTD_isError(rc) || rc != 0 || done != size) {
    throw InputError(what + ": the zstd data do not decompress (" +
                     (ZSTD_isError(rc)
                          ? std::string(ZSTD_getErrorName(rc))
                          : std::to_string(done) + " of " + std::to_string(size) + " bytes") +
                     ")");
  }
  out.resize(size);
}

}  // namespace omnivert::recording
