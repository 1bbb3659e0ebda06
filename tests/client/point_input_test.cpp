// alphactl's bounded input (client/point_input.hpp): text parsed in batches gives what one whole
// parse gives (points, header, error line numbers) wherever the batches end; every kind of input is
// accepted or refused by name; the point and line limits end endless input.
#include "client/point_input.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/io/point_formats.hpp"

namespace galpha::alphactl {
namespace {

/// A file in the temporary directory, removed with the object.
class TempFile {
 public:
  TempFile(const std::string& name, const std::string& contents)
      : path_(std::filesystem::temp_directory_path() / absl::StrCat("point_input_", getpid(), "_", name)) {
    std::ofstream(path_, std::ios::binary) << contents;
  }
  ~TempFile() { std::filesystem::remove(path_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// ReadTextPoints of `text` from a file descriptor, with `options`.
absl::StatusOr<std::vector<Point2>> ReadText(const std::string& text, const InputOptions& options) {
  TempFile file("text", text);
  std::FILE* in = std::fopen(file.path().c_str(), "rb");
  absl::StatusOr<std::vector<Point2>> points = ReadTextPoints(fileno(in), "input.csv", options);
  std::fclose(in);
  return points;
}

std::string Lines(int count, const std::string& line) {
  std::string text;
  for (int i = 0; i < count; ++i) text += line;
  return text;
}

void ExpectSamePoints(const std::vector<Point2>& got, const std::vector<Point2>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].x, want[i].x) << i;
    EXPECT_EQ(got[i].y, want[i].y) << i;
  }
}

// Texts whose header, comments, bad lines and missing final newline fall on every side of batch
// ends: for every batch size, the batched read agrees with ParsePointsText on the whole, errors
// (with their line numbers) included.
TEST(PointInputTest, BatchesAgreeWithOneWholeParse) {
  const std::vector<std::string> texts = {
      "x,y\n" + Lines(40, "1,2\n3.5,-4\n"),
      Lines(30, "# comment\n\n") + "x y\n" + Lines(20, "5 6\r\n"),
      Lines(30, "# comment\n") + Lines(20, "5 6\n") + "7 8",
      Lines(25, "1;2\n") + "oops,1\n" + Lines(25, "3;4\n"),
      Lines(25, "\n") + "1,2\n" + Lines(25, "1,2\n") + "header,later\n" + Lines(5, "1,2\n"),
      "",
      Lines(5, "\n# only comments\n"),
  };
  for (size_t t = 0; t < texts.size(); ++t) {
    const absl::StatusOr<std::vector<Point2>> whole = ParsePointsText(texts[t], "input.csv");
    for (size_t batch_bytes : {1, 2, 5, 7, 16, 33, 100, 1 << 20}) {
      SCOPED_TRACE(absl::StrCat("text ", t, ", batches of ", batch_bytes, " bytes"));
      InputOptions options;
      options.batch_bytes = batch_bytes;
      const absl::StatusOr<std::vector<Point2>> batched = ReadText(texts[t], options);
      ASSERT_EQ(batched.status(), whole.status());
      if (whole.ok()) ExpectSamePoints(*batched, *whole);
    }
  }
}

// The same for weighted text (x, y, weight): batches agree with ParseWeightedPointsText on the
// whole, through the weighted read (ReadInputPointsAndCrs with --weights squared).
TEST(PointInputTest, WeightedBatchesAgreeWithOneWholeParse) {
  const std::vector<std::string> texts = {
      "x,y,r\n" + Lines(40, "1,2,0.5\n3.5,-4,-1\n"),
      Lines(30, "# comment\n\n") + "x y w\n" + Lines(20, "5 6 7\r\n"),
      Lines(25, "1;2;3\n") + "4;5\n" + Lines(25, "3;4;5\n"),
      Lines(20, "5 6 1\n") + "7 8 2",
  };
  for (size_t t = 0; t < texts.size(); ++t) {
    const absl::StatusOr<GeoreferencedPoints> whole = ParseWeightedPointsText(texts[t], "input.csv");
    TempFile file("weighted.csv", texts[t]);
    for (size_t batch_bytes : {1, 5, 16, 100, 1 << 20}) {
      SCOPED_TRACE(absl::StrCat("text ", t, ", batches of ", batch_bytes, " bytes"));
      InputOptions options;
      options.batch_bytes = batch_bytes;
      options.weights = InputOptions::Weights::kSquared;
      const absl::StatusOr<GeoreferencedPoints> batched = ReadInputPointsAndCrs(file.path(), options);
      ASSERT_EQ(batched.ok(), whole.ok()) << batched.status();
      if (!whole.ok()) {
        // The line number is the same; the source is the file's path here.
        const std::string line = std::string(whole.status().message()).substr(std::string("input.csv").size());
        EXPECT_NE(batched.status().message().find(line.substr(0, line.find(' '))), absl::string_view::npos)
            << batched.status() << " vs " << whole.status();
        continue;
      }
      ExpectSamePoints(batched->points, whole->points);
      EXPECT_EQ(batched->weights, whole->weights);
    }
  }
  // Radii are squared on the way in.
  TempFile radii("radii.csv", "0 0 3\n1 0 0.5\n");
  InputOptions options;
  options.weights = InputOptions::Weights::kRadius;
  const absl::StatusOr<GeoreferencedPoints> read = ReadInputPointsAndCrs(radii.path(), options);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->weights, std::vector<double>({9.0, 0.25}));
}

TEST(PointInputTest, MorePointsThanTheLimitIsResourceExhausted) {
  InputOptions options;
  options.max_points = 10;
  options.batch_bytes = 8;
  EXPECT_TRUE(ReadText(Lines(10, "1 2\n"), options).ok());
  const absl::StatusOr<std::vector<Point2>> over = ReadText(Lines(11, "1 2\n"), options);
  EXPECT_EQ(over.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(over.status().message().find("more than 10 points"), std::string::npos) << over.status();

  TempFile bin("over.bin", std::string("\x0b\0\0\0\0\0\0\0", 8) + std::string(11 * 16, '\0'));
  const absl::StatusOr<std::vector<Point2>> bin_over = ReadInputPoints(bin.path(), options);
  EXPECT_EQ(bin_over.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(bin_over.status().message().find("room for 11 points"), std::string::npos) << bin_over.status();
}

TEST(PointInputTest, ALongLineNamesItsNumberOffsetAndTheLimit) {
  InputOptions options;
  options.max_line_bytes = 10;
  options.batch_bytes = 4;
  EXPECT_TRUE(ReadText("12345,7890\n1 2\n", options).ok());
  const absl::StatusOr<std::vector<Point2>> long_line = ReadText("1 2\n3 4\n12345678901\n", options);
  EXPECT_EQ(long_line.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(long_line.status().message(),
            "input.csv: line 3 (from byte offset 8) is longer than 10 bytes, the limit for one line of delimited text");
  // Endless bytes without a newline end at the limit, whatever the reads' sizes.
  options.max_line_bytes = size_t{64} << 10;
  const absl::StatusOr<std::vector<Point2>> zeros = ReadText(std::string(size_t{1} << 20, '\0'), options);
  EXPECT_EQ(zeros.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(zeros.status().message().find("line 1 (from byte offset 0)"), std::string::npos) << zeros.status();
}

TEST(PointInputTest, FilesAreReadOrRefusedByKind) {
  const InputOptions options;
  TempFile csv("points.csv", "x,y\n0,0\n1,0\n0,1\n");
  ASSERT_TRUE(ReadInputPoints(csv.path(), options).ok());
  EXPECT_EQ(ReadInputPoints(csv.path(), options)->size(), 3u);

  const absl::Status missing = ReadInputPoints("/nonexistent/points.csv", options).status();
  EXPECT_EQ(missing.code(), absl::StatusCode::kNotFound) << missing;
  const absl::Status directory = ReadInputPoints(std::filesystem::temp_directory_path(), options).status();
  EXPECT_EQ(directory.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(directory.message().find("is a directory"), std::string::npos) << directory;
  const absl::Status device = ReadInputPoints("/dev/zero", options).status();
  EXPECT_EQ(device.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(device.message().find("'/dev/zero' is a character device"), std::string::npos) << device;
}

TEST(PointInputTest, NamedPipesCarryDelimitedTextOnly) {
  const std::string dir = std::filesystem::temp_directory_path() / absl::StrCat("point_input_fifo_", getpid());
  std::filesystem::create_directories(dir);
  const std::string text_pipe = dir + "/points", bin_pipe = dir + "/points.bin";
  ASSERT_EQ(mkfifo(text_pipe.c_str(), 0600), 0);
  ASSERT_EQ(mkfifo(bin_pipe.c_str(), 0600), 0);
  // Opening a pipe for reading waits for its writer.
  std::thread writer([&] { std::ofstream(text_pipe) << "0 0\n1 0\n0 1\n1 1\n"; });
  const absl::StatusOr<std::vector<Point2>> points = ReadInputPoints(text_pipe, InputOptions{});
  writer.join();
  ASSERT_TRUE(points.ok()) << points.status();
  EXPECT_EQ(points->size(), 4u);

  const absl::Status bin = ReadInputPoints(bin_pipe, InputOptions{}).status();
  EXPECT_EQ(bin.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bin.message().find("is a named pipe"), std::string::npos) << bin;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace galpha::alphactl
