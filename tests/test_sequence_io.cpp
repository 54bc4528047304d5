// The YCBInEOAT reader: a small sequence written here, every kind of bad input, and the shared
// real sequences when they are present.
#include <doctest/doctest.h>

#include <atomic>
#include <fstream>
#include <thread>
#include <vector>

#include "bundletrack/io/png_decoder.hpp"
#include "bundletrack/io/read_ahead.hpp"
#include "bundletrack/io/rgbd_sequence.hpp"
#include "shared_data.hpp"
#include "temp_dir.hpp"

namespace bt = bundletrack;
namespace fs = std::filesystem;

namespace {

void writeText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// Three 80x60 frames of a fronto-parallel wall at 1 m with a square "object" at 0.8 m.
void writeValidSequence(const fs::path& root) {
  for (const char* dir : {"rgb", "depth", "masks", "annotated_poses", "model"}) fs::create_directories(root / dir);
  writeText(root / "cam_K.txt", "100 0 39.5\n0 100 29.5\n0 0 1\n");
  for (const char* name : {"2", "10", "1"}) {  // numeric names, deliberately unpadded and unordered
    cv::Mat color(60, 80, CV_8UC3, cv::Scalar(40, 120, 200));
    cv::Mat depth(60, 80, CV_16UC1, cv::Scalar(1000));
    depth(cv::Rect(30, 20, 20, 20)).setTo(800);
    cv::Mat mask(60, 80, CV_8UC1, cv::Scalar(0));
    mask(cv::Rect(30, 20, 20, 20)).setTo(255);
    cv::imwrite((root / "rgb" / (std::string(name) + ".png")).string(), color);
    cv::imwrite((root / "depth" / (std::string(name) + ".png")).string(), depth);
    cv::imwrite((root / "masks" / (std::string(name) + ".png")).string(), mask);
    writeText(root / "annotated_poses" / (std::string(name) + ".txt"), "1 0 0 0\n0 1 0 0\n0 0 1 0.8\n0 0 0 1\n");
  }
  writeText(root / "model" / "points.xyz", "0 0 0\n0.01 0 0\n\n0 0.01 0 1 2 3\n");
}

// Runs `load` and checks that it throws InputError naming `file` and mentioning `problem`.
template <typename F>
void checkInputError(F&& load, const fs::path& file, const std::string& problem) {
  CAPTURE(file);
  CAPTURE(problem);
  try {
    load();
    FAIL("no InputError was thrown");
  } catch (const bt::InputError& error) {
    CAPTURE(error.what());
    CHECK(error.source() == file);
    CHECK(std::string(error.what()).find(file.string()) != std::string::npos);
    CHECK(error.problem().find(problem) != std::string::npos);
  }
}

}  // namespace

TEST_CASE("a valid sequence reads in numeric name order with metric depth, masks, poses and model") {
  TempDir dir("seq");
  writeValidSequence(dir.path());
  const bt::io::RgbdSequence sequence(dir.path());
  REQUIRE(sequence.size() == 3);
  CHECK(sequence.frameNames() == std::vector<std::string>{"1", "2", "10"});
  CHECK(sequence.camera().fx == 100.0);
  CHECK(sequence.camera().cy == 29.5);
  CHECK(sequence.imageSize() == cv::Size(80, 60));

  const bt::RgbdFrame frame = sequence.frame(2);
  CHECK(frame.name == "10");
  CHECK(frame.depth.type() == CV_32FC1);
  CHECK(frame.depth.at<float>(5, 5) == doctest::Approx(1.0f));
  CHECK(frame.depth.at<float>(30, 40) == doctest::Approx(0.8f));
  CHECK(cv::countNonZero(frame.mask) == 400);
  const cv::Vec3f p = frame.points.at<cv::Vec3f>(30, 40);  // (40 - 39.5) * 0.8 / 100
  CHECK(p[0] == doctest::Approx(0.004f));
  CHECK(p[2] == doctest::Approx(0.8f));

  REQUIRE(sequence.hasGroundTruth());
  CHECK(sequence.groundTruthPose(1).translation().z() == doctest::Approx(0.8));
  REQUIRE(sequence.hasModel());
  CHECK(sequence.modelPoints().size() == 3);
}

TEST_CASE("bad input raises InputError naming the file and the problem") {
  TempDir dir("bad");
  const fs::path root = dir.path();
  writeValidSequence(root);
  const auto open = [&] { return bt::io::RgbdSequence(root); };

  SUBCASE("missing sequence directory") {
    checkInputError([&] { bt::io::RgbdSequence(root / "nope"); }, root / "nope", "not found");
  }
  SUBCASE("missing rgb directory") {
    fs::remove_all(root / "rgb");
    checkInputError(open, root / "rgb", "directory not found");
  }
  SUBCASE("missing cam_K.txt") {
    fs::remove(root / "cam_K.txt");
    checkInputError(open, root / "cam_K.txt", "file not found");
  }
  // Intrinsics files that must be refused, with the problem each one's message names.
  const struct {
    const char* text;
    const char* problem;
  } bad_intrinsics[] = {{"-100 0 39.5\n0 100 29.5\n0 0 1\n", "focal lengths"},
                        {"100 0 nan\n0 100 29.5\n0 0 1\n", "non-finite"},
                        {"100 0 39.5\n0 100 29.5\n", "expected 9 numbers"},
                        {"fx=100 0 39.5\n0 100 29.5\n0 0 1\n", "is not a number"},
                        {"100 0 319.5\n0 100 239.5\n0 0 1\n", "principal point"},
                        {"1000000 0 39.5\n0 1000000 29.5\n0 0 1\n", "field of view of 0.0"},  // K of mm, not px
                        {"0.5 0 39.5\n0 0.5 29.5\n0 0 1\n", "field of view of 17"},
                        {"100 0 39.5\n0 10 29.5\n0 0 1\n", "fx / fy = 10"}};
  for (const auto& bad : bad_intrinsics) {
    SUBCASE(bad.problem) {
      writeText(root / "cam_K.txt", bad.text);
      checkInputError(open, root / "cam_K.txt", bad.problem);
    }
  }
  SUBCASE("a directory where cam_K.txt belongs") {
    fs::remove(root / "cam_K.txt");
    fs::create_directory(root / "cam_K.txt");
    checkInputError(open, root / "cam_K.txt", "is a directory");
  }
  SUBCASE("depth in 0.1 mm read as millimetres") {
    // The wall at 1 m and the object at 0.8 m read as 10 m and 8 m: the object's depth is one a
    // sensor could measure, the whole frame's median is beyond twice a Kinect's 4 m.
    for (const char* name : {"1", "2", "10"}) {
      cv::Mat depth(60, 80, CV_16UC1, cv::Scalar(10000));
      depth(cv::Rect(30, 20, 20, 20)).setTo(8000);
      cv::imwrite((root / "depth" / (std::string(name) + ".png")).string(), depth);
    }
    checkInputError(open, root / "depth" / "1.png", "median depth of the whole first frame is 10.000000 m");
    checkInputError(open, root / "depth" / "1.png", "images in 0.1 mm need 0.0001");
    bt::io::SequenceSettings settings;
    settings.depth_scale = 0.0001;
    CHECK(bt::io::RgbdSequence(root, settings).frame(0).depth.at<float>(30, 40) == doctest::Approx(0.8f));
    CHECK(bt::io::RgbdSequence(root, settings).warnings().empty());
    settings.depth_scale = 0.0;
    settings.frame.sensor = bt::DepthNoise::activeStereo();  // specified to 10 m: 10 m is within twice that
    CHECK(bt::io::RgbdSequence(root, settings).frame(0).depth.at<float>(30, 40) == doctest::Approx(8.0f));
    CHECK(bt::io::RgbdSequence(root, settings).warnings().empty());
  }
  SUBCASE("depth in 0.2 mm read as millimetres") {
    // The wall at 1.2 m and the object at 1 m read as 6 m and 5 m: beyond a Kinect's 4 m but
    // within twice that, so a caution naming the likely unit, not an error.
    for (const char* name : {"1", "2", "10"}) {
      cv::Mat depth(60, 80, CV_16UC1, cv::Scalar(6000));
      depth(cv::Rect(30, 20, 20, 20)).setTo(5000);
      cv::imwrite((root / "depth" / (std::string(name) + ".png")).string(), depth);
    }
    const bt::io::RgbdSequence sequence(root);
    REQUIRE(sequence.warnings().size() == 1);
    CHECK(sequence.warnings()[0].find("1.png: median depth of the whole first frame is 6.000000 m") != std::string::npos);
    CHECK(sequence.warnings()[0].find("more than the 4.00 m that the sensor (sensor.model) is specified for") !=
          std::string::npos);
    CHECK(sequence.warnings()[0].find("0.2 mm or TUM RGB-D's 1/5000: 0.0002") != std::string::npos);
    bt::io::SequenceSettings settings;
    settings.depth_scale = 0.0002;
    CHECK(bt::io::RgbdSequence(root, settings).warnings().empty());
    settings.depth_scale = 0.0;
    settings.frame.sensor = bt::DepthNoise::timeOfFlight();  // specified to 5.46 m
    CHECK(bt::io::RgbdSequence(root, settings).warnings().size() == 1);
    settings.frame.sensor = bt::DepthNoise::activeStereo();  // specified to 10 m
    CHECK(bt::io::RgbdSequence(root, settings).warnings().empty());
  }
  SUBCASE("missing first mask") {
    fs::remove(root / "masks" / "1.png");
    checkInputError(open, root / "masks" / "1.png", "needs an object mask");
  }
  SUBCASE("empty first mask") {
    cv::imwrite((root / "masks" / "1.png").string(), cv::Mat(60, 80, CV_8UC1, cv::Scalar(0)));
    checkInputError(open, root / "masks" / "1.png", "mask is empty");
  }
  SUBCASE("unreadable colour image") {
    writeText(root / "rgb" / "2.png", "not a png");
    checkInputError([&] { open().frame(1); }, root / "rgb" / "2.png", "not a PNG or JPEG image");
  }
  SUBCASE("a PNG header over garbage") {
    writeText(root / "rgb" / "2.png", std::string("\x89PNG\r\n\x1a\n", 8) + "garbage IEND");
    checkInputError([&] { open().frame(1); }, root / "rgb" / "2.png", "corrupt PNG image");
  }
  SUBCASE("another format's file: OpenCV's DICOM decoder aborted on this one (fuzz_sequence_files)") {
    std::string dicom(128, '\xff');
    dicom += "DICM\xffUN";
    writeText(root / "depth" / "2.png", dicom);
    checkInputError([&] { open().frame(1); }, root / "depth" / "2.png", "not a PNG or JPEG image");
  }
  // Truncated files still decode (the rest grey or black) unless their end marker is checked.
  const auto truncate = [](const fs::path& path) { fs::resize_file(path, fs::file_size(path) / 2); };
  SUBCASE("truncated colour PNG") {
    truncate(root / "rgb" / "2.png");
    checkInputError([&] { open().frame(1); }, root / "rgb" / "2.png", "truncated or corrupt image");
  }
  SUBCASE("truncated colour JPEG") {
    fs::remove(root / "rgb" / "2.png");
    cv::Mat noise(60, 80, CV_8UC3);
    cv::randu(noise, 0, 255);  // incompressible: the entropy-coded data fills the file
    cv::imwrite((root / "rgb" / "2.jpg").string(), noise);
    CHECK(open().frame(1).color.size() == cv::Size(80, 60));  // whole, it reads
    truncate(root / "rgb" / "2.jpg");
    const cv::Mat half = cv::imread((root / "rgb" / "2.jpg").string());
    CHECK(half.size() == cv::Size(80, 60));  // what OpenCV alone returns: an image, its lower part grey
    checkInputError([&] { open().frame(1); }, root / "rgb" / "2.jpg", "truncated or corrupt image");
  }
  SUBCASE("truncated depth PNG") {
    truncate(root / "depth" / "2.png");
    checkInputError([&] { open().frame(1); }, root / "depth" / "2.png", "truncated or corrupt image");
  }
  SUBCASE("missing depth image") {
    fs::remove(root / "depth" / "2.png");
    checkInputError([&] { open().frame(1); }, root / "depth" / "2.png", "file not found");
  }
  SUBCASE("depth image that is not 16-bit") {
    cv::imwrite((root / "depth" / "2.png").string(), cv::Mat(60, 80, CV_8UC3, cv::Scalar(1, 2, 3)));
    checkInputError([&] { open().frame(1); }, root / "depth" / "2.png", "16-bit");
  }
  SUBCASE("depth and colour of different sizes") {
    cv::imwrite((root / "depth" / "2.png").string(), cv::Mat(48, 64, CV_16UC1, cv::Scalar(900)));
    checkInputError([&] { open().frame(1); }, root / "depth" / "2.png", "64x48");
  }
  SUBCASE("mask of a different size") {
    cv::imwrite((root / "masks" / "2.png").string(), cv::Mat(30, 40, CV_8UC1, cv::Scalar(255)));
    checkInputError([&] { open().frame(1); }, root / "masks" / "2.png", "40x30");
  }
  SUBCASE("all-invalid depth") {
    cv::imwrite((root / "depth" / "2.png").string(), cv::Mat(60, 80, CV_16UC1, cv::Scalar(0)));
    checkInputError([&] { open().frame(1); }, root / "depth" / "2.png", "no valid pixel");
  }
  SUBCASE("pose that is not a rigid transform") {
    writeText(root / "annotated_poses" / "2.txt", "2 0 0 0\n0 1 0 0\n0 0 1 0.8\n0 0 0 1\n");
    checkInputError([&] { open().groundTruthPose(1); }, root / "annotated_poses" / "2.txt", "not a rotation");
  }
  SUBCASE("model file with a malformed line") {
    writeText(root / "model" / "points.xyz", "0 0 0\n0.1 x 0\n");
    checkInputError([&] { open().modelPoints(); }, root / "model" / "points.xyz", "line 2");
  }
}

namespace {

void appendBigEndian32(std::vector<uchar>& out, std::uint32_t value) {
  for (const int shift : {24, 16, 8, 0}) out.push_back(uchar(value >> shift));
}

// A PNG chunk with its length and CRC.
void appendChunk(std::vector<uchar>& png, const std::string& type, const std::vector<uchar>& data) {
  appendBigEndian32(png, std::uint32_t(data.size()));
  std::vector<uchar> typed(type.begin(), type.end());
  typed.insert(typed.end(), data.begin(), data.end());
  png.insert(png.end(), typed.begin(), typed.end());
  appendBigEndian32(png, std::uint32_t(libdeflate_crc32(0, typed.data(), typed.size())));
}

// Writes the CRC of the chunk at byte `chunk` of `png` anew, after its data was changed.
void rewriteCrc(std::vector<uchar>& png, std::size_t chunk) {
  const std::uint32_t length = bt::io::detail::bigEndian32(&png[chunk]);
  const std::uint32_t crc = std::uint32_t(libdeflate_crc32(0, &png[chunk + 4], length + 4));
  for (int k = 0; k < 4; ++k) png[chunk + 8 + length + std::size_t(k)] = uchar(crc >> (24 - 8 * k));
}

// A PNG of `image` (8-bit grey, RGB from BGR, RGBA from BGRA, or 16-bit grey) whose row v is
// written with filter type v % 5 (PNG specification, section 9.2), so that every filter is used;
// OpenCV's encoder chooses its own filters.
std::vector<uchar> pngWithEveryFilter(const cv::Mat& image) {
  const int channels = image.channels(), bpp = channels * int(image.elemSize1());
  const int colour_type = channels == 1 ? 0 : channels == 3 ? 2 : 6;
  const std::size_t row_bytes = std::size_t(bpp) * std::size_t(image.cols);
  std::vector<uchar> previous(row_bytes, 0), filtered;
  for (int v = 0; v < image.rows; ++v) {
    std::vector<uchar> row(row_bytes);  // PNG's byte order: RGB(A), 16-bit big-endian
    for (int u = 0; u < image.cols; ++u) {
      uchar* px = &row[std::size_t(u * bpp)];
      if (image.depth() == CV_16U) {
        const std::uint16_t z = image.at<std::uint16_t>(v, u);
        px[0] = uchar(z >> 8), px[1] = uchar(z & 0xff);
      } else {
        const uchar* in = image.ptr(v) + u * channels;
        for (int c = 0; c < channels; ++c) px[c] = in[c];
        if (channels >= 3) std::swap(px[0], px[2]);
      }
    }
    const int filter = v % 5;
    filtered.push_back(uchar(filter));
    for (std::size_t i = 0; i < row_bytes; ++i) {
      const int a = i >= std::size_t(bpp) ? row[i - std::size_t(bpp)] : 0, b = previous[i];
      const int c = i >= std::size_t(bpp) ? previous[i - std::size_t(bpp)] : 0;
      const int prediction = filter == 1 ? a : filter == 2 ? b : filter == 3 ? (a + b) / 2 : filter == 4 ? bt::io::detail::paeth(a, b, c) : 0;
      filtered.push_back(uchar(row[i] - prediction));
    }
    previous = row;
  }
  std::vector<uchar> compressed(libdeflate_zlib_compress_bound(nullptr, filtered.size()));
  libdeflate_compressor* compressor = libdeflate_alloc_compressor(6);
  compressed.resize(libdeflate_zlib_compress(compressor, filtered.data(), filtered.size(), compressed.data(), compressed.size()));
  libdeflate_free_compressor(compressor);
  std::vector<uchar> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A}, header;
  appendBigEndian32(header, std::uint32_t(image.cols));
  appendBigEndian32(header, std::uint32_t(image.rows));
  header.insert(header.end(), {uchar(8 * image.elemSize1()), uchar(colour_type), 0, 0, 0});
  appendChunk(png, "IHDR", header);
  const std::size_t half = compressed.size() / 2;  // image data in two IDAT chunks, as encoders split it
  appendChunk(png, "IDAT", std::vector<uchar>(compressed.begin(), compressed.begin() + std::ptrdiff_t(half)));
  appendChunk(png, "IDAT", std::vector<uchar>(compressed.begin() + std::ptrdiff_t(half), compressed.end()));
  appendChunk(png, "IEND", {});
  return png;
}

bool samePixels(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

}  // namespace

TEST_CASE("PNG decoding gives OpenCV's pixels for the layouts of RGB-D recordings, with every filter") {
  cv::RNG rng(7);
  for (const int type : {CV_8UC1, CV_16UC1, CV_8UC3, CV_8UC4}) {
    // Odd sizes; noise and a smooth ramp (on which encoders pick different filters).
    cv::Mat noise(23, 37, type), ramp(23, 37, type);
    rng.fill(noise, cv::RNG::UNIFORM, 0, type == CV_16UC1 ? 65536 : 256);
    for (int v = 0; v < ramp.rows; ++v)
      for (int u = 0; u < ramp.cols * ramp.channels(); ++u) {
        const int value = 40 * v + 7 * u;
        if (type == CV_16UC1) ramp.at<std::uint16_t>(v, u) = std::uint16_t(800 + value);
        else ramp.ptr(v)[u] = uchar(value);
      }
    for (const cv::Mat& image : {noise, ramp}) {
      std::vector<uchar> by_opencv;
      cv::imencode(".png", image, by_opencv);
      for (const std::vector<uchar>& png : {by_opencv, pngWithEveryFilter(image)}) {
        CAPTURE(type);
        const bt::io::PngDecoding ours = bt::io::decodePng(png, cv::IMREAD_UNCHANGED);
        REQUIRE(ours.error.empty());
        CHECK(samePixels(ours.image, image));
        CHECK(samePixels(ours.image, cv::imdecode(png, cv::IMREAD_UNCHANGED)));
        const bt::io::PngDecoding colour = bt::io::decodePng(png, cv::IMREAD_COLOR);
        if (image.channels() == 1) {  // grey as colour: left to OpenCV
          CHECK((colour.image.empty() && colour.error.empty()));
        } else {
          CHECK(samePixels(colour.image, cv::imdecode(png, cv::IMREAD_COLOR)));
          CHECK(colour.image.channels() == 3);
        }
        CHECK(samePixels(bt::io::decodeImage(png, cv::IMREAD_COLOR, "x.png"), cv::imdecode(png, cv::IMREAD_COLOR)));
      }
    }
  }
}

TEST_CASE("a corrupt PNG is an error naming the chunk or the stream, a damaged ancillary chunk is skipped") {
  cv::Mat image(20, 30, CV_16UC1);
  cv::RNG(3).fill(image, cv::RNG::UNIFORM, 500, 5000);
  const std::vector<uchar> png = pngWithEveryFilter(image);
  const std::size_t first_idat = 8 + 25;  // signature, IHDR (12 + 13 bytes)
  SUBCASE("a flipped byte in the image data fails the chunk's CRC") {
    std::vector<uchar> bad = png;
    bad[first_idat + 8 + 3] ^= 0x10;
    const bt::io::PngDecoding ours = bt::io::decodePng(bad, cv::IMREAD_UNCHANGED);
    CHECK(ours.image.empty());
    CHECK(ours.error == "chunk IDAT fails its CRC");
    checkInputError([&] { bt::io::decodeImage(bad, cv::IMREAD_UNCHANGED, "depth/7.png"); }, "depth/7.png",
                    "corrupt PNG image: chunk IDAT fails its CRC");
  }
  SUBCASE("a broken zlib stream under a right CRC") {
    std::vector<uchar> bad = png;
    const std::uint32_t length = bt::io::detail::bigEndian32(&bad[first_idat]);
    for (std::size_t i = 2; i < length; ++i) bad[first_idat + 8 + i] = 0xff;  // past the zlib header
    rewriteCrc(bad, first_idat);
    CHECK(bt::io::decodePng(bad, cv::IMREAD_UNCHANGED).error == "corrupt or truncated image data (zlib stream)");
  }
  SUBCASE("a header that claims more pixels than the image data can hold") {
    std::vector<uchar> bad = png;
    bad[8 + 8 + 1] = 0x01;  // width 30 -> 65,566 (big-endian bytes 0x00 0x01 0x00 0x1e)
    rewriteCrc(bad, 8);
    const bt::io::PngDecoding ours = bt::io::decodePng(bad, cv::IMREAD_UNCHANGED);
    CHECK(ours.image.empty());
    CHECK(ours.error.find("cannot fill a 65566 x 20 image") != std::string::npos);
  }
  SUBCASE("a text chunk with a wrong CRC") {
    std::vector<uchar> text_chunk;
    appendChunk(text_chunk, "tEXt", {'a', 0, 'b'});
    text_chunk.back() ^= 1;
    std::vector<uchar> with_text = png;
    with_text.insert(with_text.begin() + std::ptrdiff_t(first_idat), text_chunk.begin(), text_chunk.end());
    const bt::io::PngDecoding ours = bt::io::decodePng(with_text, cv::IMREAD_UNCHANGED);
    CHECK(ours.error.empty());
    CHECK(samePixels(ours.image, image));
    CHECK(samePixels(ours.image, cv::imdecode(with_text, cv::IMREAD_UNCHANGED)));
  }
}

TEST_CASE("read-ahead hands items over in order and tells the reader whether the consumer has one waiting") {
  // Capacity 1: the reader starts an item only when the consumer has taken the one before, so it
  // never has a backlog. Capacity 4 and a consumer that takes nothing until four items are read:
  // the first is read with nothing waiting, the next three with one or more waiting.
  for (const std::size_t capacity : {std::size_t(1), std::size_t(4)}) {
    CAPTURE(capacity);
    std::vector<int> backlogs(6, -1);
    std::atomic<int> read{0};
    bt::io::ReadAhead<int> items(
        6,
        [&](std::size_t i, bool backlog) {
          backlogs[i] = backlog ? 1 : 0;
          ++read;
          return int(i) * 10;
        },
        capacity);
    if (capacity == 4)
      while (read.load() < 4) std::this_thread::yield();
    for (int i = 0; i < 6; ++i) CHECK(items.next() == 10 * i);
    if (capacity == 1) CHECK(backlogs == std::vector<int>{0, 0, 0, 0, 0, 0});
    else CHECK(std::vector<int>(backlogs.begin(), backlogs.begin() + 4) == std::vector<int>{0, 1, 1, 1});
  }
}

TEST_CASE("shared real sequences: conventions agree with the ground truth and the object model") {
  const fs::path data = sharedDataDir() / "7scenes_objects";
  if (!fs::is_directory(data)) {
    MESSAGE("SKIPPED: " << data << " is absent");
    return;
  }
  for (const std::string name : {"mug_1", "magazines_1", "container_1"}) {
    CAPTURE(name);
    const bt::io::RgbdSequence sequence(data / name);
    CHECK(sequence.size() > 100);
    REQUIRE(sequence.hasGroundTruth());
    const auto model = sequence.modelPoints();
    const bt::RgbdFrame frame = sequence.frame(0);
    CHECK(frame.color.size() == cv::Size(640, 480));
    // Masked points taken into the object frame by the annotated pose must lie on the object's
    // model points (4 mm voxels, a few mm of KinectFusion error): a wrong depth scale, pixel
    // convention or pose direction moves them by centimetres.
    const bt::SE3f obj_from_cam = sequence.groundTruthPose(0).inverse().cast<float>();
    double sum = 0.0;
    int count = 0, valid_in_mask = 0;
    for (int v = 0; v < frame.mask.rows; v += 2) {
      for (int u = 0; u < frame.mask.cols; u += 2) {
        if (!frame.mask.at<uchar>(v, u)) continue;
        const cv::Vec3f p = frame.points.at<cv::Vec3f>(v, u);
        if (p[2] <= 0.0f) continue;
        ++valid_in_mask;
        const Eigen::Vector3f q = obj_from_cam * Eigen::Vector3f(p[0], p[1], p[2]);
        float best = std::numeric_limits<float>::max();
        for (const auto& m : model) best = std::min(best, (m - q).squaredNorm());
        sum += std::sqrt(best);
        ++count;
      }
    }
    REQUIRE(count > 100);
    MESSAGE(name << ": " << count << " masked points, mean distance to the model " << 1000.0 * sum / count << " mm");
    CHECK(sum / count < 0.006);
  }
}
