#pragma once

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <libdeflate.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace bundletrack::io {

/// What decodePng makes of a file: the image, or why the file is not a valid PNG.
struct PngDecoding {
  cv::Mat image;  ///< empty with `error` set, or where the layout is not one decodePng handles
  std::string error;  ///< the file is not a valid PNG (a corrupt chunk, a bad zlib stream)
};

namespace detail {

inline std::uint32_t bigEndian32(const uchar* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | std::uint32_t(p[3]);
}

/// PNG's Paeth predictor (PNG specification, section 9.4): of left a, above b and upper left c,
/// the one nearest to a + b - c, ties in the order a, b, c.
inline int paeth(int a, int b, int c) {
  const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
  return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

/// Undoes the filter of one scanline in place (PNG specification, section 9.2); `above` is the
/// previous line after its own unfiltering (zeros for the first), Bpp the bytes per pixel. The
/// bytes to the left are carried in registers: each output byte depends on the one Bpp before.
template <std::size_t Bpp>
bool unfilterLine(int filter, uchar* line, const uchar* above, std::size_t length) {
  uchar left[Bpp], upper_left[Bpp];
  switch (filter) {
    case 0:
      return true;
    case 1:
      for (std::size_t k = 0; k < Bpp; ++k) left[k] = line[k];
      for (std::size_t i = Bpp; i < length; i += Bpp)
        for (std::size_t k = 0; k < Bpp; ++k) line[i + k] = left[k] = uchar(line[i + k] + left[k]);
      return true;
    case 2:
      for (std::size_t i = 0; i < length; ++i) line[i] = uchar(line[i] + above[i]);
      return true;
    case 3:
      for (std::size_t k = 0; k < Bpp; ++k) line[k] = left[k] = uchar(line[k] + (above[k] >> 1));
      for (std::size_t i = Bpp; i < length; i += Bpp)
        for (std::size_t k = 0; k < Bpp; ++k) line[i + k] = left[k] = uchar(line[i + k] + ((left[k] + above[i + k]) >> 1));
      return true;
    case 4:
      for (std::size_t k = 0; k < Bpp; ++k) line[k] = left[k] = uchar(line[k] + above[k]), upper_left[k] = above[k];
      for (std::size_t i = Bpp; i < length; i += Bpp)
        for (std::size_t k = 0; k < Bpp; ++k) {
          line[i + k] = left[k] = uchar(line[i + k] + paeth(left[k], above[i + k], upper_left[k]));
          upper_left[k] = above[i + k];
        }
      return true;
    default:
      return false;
  }
}

inline bool unfilterLine(int filter, uchar* line, const uchar* above, std::size_t length, std::size_t bpp) {
  switch (bpp) {
    case 1: return unfilterLine<1>(filter, line, above, length);
    case 2: return unfilterLine<2>(filter, line, above, length);
    case 3: return unfilterLine<3>(filter, line, above, length);
    default: return unfilterLine<4>(filter, line, above, length);
  }
}

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

}  // namespace detail

/// Decodes the PNG layouts RGB-D recordings are written in, exactly as cv::imdecode does, with
/// libdeflate's inflate (about twice zlib's speed) in place of libpng's: non-interlaced 8-bit grey,
/// RGB and RGBA and 16-bit grey (depth), read with cv::IMREAD_UNCHANGED (grey, BGR, BGRA, 16-bit
/// grey) or cv::IMREAD_COLOR (BGR; RGBA loses its alpha). As libpng, it checks the CRC of every
/// chunk (an ancillary one that fails is skipped, a critical one is an error) and the zlib
/// stream's Adler-32; the image data must fill the image exactly. Any other layout or flag
/// (palette, interlacing, transparency or orientation chunks, 16-bit colour, grey read as colour)
/// gives an empty image and no error: the caller decodes it with OpenCV.
inline PngDecoding decodePng(const std::vector<uchar>& bytes, int flags) {
  static constexpr uchar kSignature[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  PngDecoding out;
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kSignature, 8) != 0) return out;
  if (flags != cv::IMREAD_UNCHANGED && flags != cv::IMREAD_COLOR) return out;
  std::uint32_t width = 0, height = 0;
  int bit_depth = 0, colour_type = -1;
  // Buffers kept per thread: a fresh one of a frame's size would be mapped and faulted in anew.
  static thread_local std::vector<uchar> compressed, raw;
  compressed.clear();
  bool ended = false;
  for (std::size_t at = 8; !ended;) {
    if (bytes.size() - at < 12) return {{}, "the file ends at byte " + std::to_string(at) + " before its IEND chunk"};
    const std::uint32_t length = detail::bigEndian32(&bytes[at]);
    if (length > bytes.size() - at - 12) return {{}, "chunk at byte " + std::to_string(at) + " runs past the end of the file"};
    const uchar* type = &bytes[at + 4];
    const uchar* data = type + 4;
    const std::string name(reinterpret_cast<const char*>(type), 4);
    const bool ancillary = (type[0] & 0x20) != 0;
    if (std::uint32_t(libdeflate_crc32(0, type, length + 4)) != detail::bigEndian32(data + length)) {
      if (!ancillary) return {{}, "chunk " + name + " fails its CRC"};
      at += std::size_t(length) + 12;  // an ancillary chunk with a bad CRC is skipped, as libpng does
      continue;
    }
    if (name == "IHDR") {
      if (length != 13) return {{}, "IHDR chunk of " + std::to_string(length) + " bytes"};
      width = detail::bigEndian32(data);
      height = detail::bigEndian32(data + 4);
      bit_depth = data[8];
      colour_type = data[9];
      if (data[10] != 0 || data[11] != 0) return {{}, "unknown compression or filter method"};
      if (data[12] != 0) return out;  // interlaced
    } else if (name == "IDAT") {
      compressed.insert(compressed.end(), data, data + length);
    } else if (name == "IEND") {
      ended = true;
    } else if (name == "PLTE" || name == "tRNS" || name == "eXIf" || !ancillary) {
      return out;  // a palette, transparency, an orientation or an unknown critical chunk: OpenCV's business
    }
    at += std::size_t(length) + 12;
  }
  if (width == 0 || height == 0) return {{}, "no IHDR chunk or an empty image"};
  // OpenCV's own limits on a decoded image's size (CV_IO_MAX_IMAGE_WIDTH / _HEIGHT / _PIXELS).
  if (width > (1u << 20) || height > (1u << 20) || std::uint64_t(width) * height > (1ull << 30)) return out;
  const bool grey = colour_type == 0, rgb = colour_type == 2, rgba = colour_type == 6;
  const std::size_t channels = grey ? 1 : rgb ? 3 : rgba ? 4 : 0;
  const bool handled = (bit_depth == 8 && channels > 0 && (flags == cv::IMREAD_UNCHANGED || !grey)) ||
                       (bit_depth == 16 && grey && flags == cv::IMREAD_UNCHANGED);
  if (!handled) return out;
  const std::size_t bpp = channels * std::size_t(bit_depth / 8), row_bytes = bpp * width;
  // Deflate expands at most 1032-fold: a header that claims more than its data can hold is refused
  // before the image's buffer is allocated.
  if ((row_bytes + 1) * height > 1032 * compressed.size() + 1032)
    return {{}, "image data of " + std::to_string(compressed.size()) + " bytes cannot fill a " + std::to_string(width) + " x " +
                    std::to_string(height) + " image"};
  raw.resize((row_bytes + 1) * height);
  static thread_local std::unique_ptr<libdeflate_decompressor, detail::DecompressorDeleter> inflater(
      libdeflate_alloc_decompressor());
  if (!inflater) throw std::bad_alloc();
  std::size_t produced = 0;
  if (libdeflate_zlib_decompress(inflater.get(), compressed.data(), compressed.size(), raw.data(), raw.size(), &produced) !=
          LIBDEFLATE_SUCCESS ||
      produced != raw.size())
    return {{}, "corrupt or truncated image data (zlib stream)"};
  const int out_channels = flags == cv::IMREAD_COLOR ? 3 : int(channels);
  cv::Mat image(int(height), int(width), CV_MAKETYPE(bit_depth == 16 ? CV_16U : CV_8U, out_channels));
  std::vector<uchar> zeros(row_bytes, 0);
  const uchar* above = zeros.data();
  for (std::uint32_t v = 0; v < height; ++v) {
    uchar* line = &raw[v * (row_bytes + 1)];
    if (!detail::unfilterLine(line[0], line + 1, above, row_bytes, bpp))
      return {{}, "unknown filter type " + std::to_string(line[0]) + " in row " + std::to_string(v)};
    const uchar* pixels = line + 1;
    above = pixels;
    if (bit_depth == 16) {
      auto* row = image.ptr<std::uint16_t>(int(v));
      for (std::uint32_t u = 0; u < width; ++u) row[u] = std::uint16_t(pixels[2 * u] << 8 | pixels[2 * u + 1]);
    } else if (channels == 1) {
      std::memcpy(image.ptr(int(v)), pixels, row_bytes);
    } else {  // RGB(A) -> BGR(A), the alpha dropped for IMREAD_COLOR
      uchar* row = image.ptr(int(v));
      for (std::uint32_t u = 0; u < width; ++u, row += out_channels, pixels += channels) {
        row[0] = pixels[2], row[1] = pixels[1], row[2] = pixels[0];
        if (out_channels == 4) row[3] = pixels[3];
      }
    }
  }
  out.image = image;
  return out;
}

}  // namespace bundletrack::io
