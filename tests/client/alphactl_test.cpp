// alphactl triangulate, run as a child process: one JSON object on standard output with counts that
// agree with Euler's formula, and on failure one line on standard error and a non-zero exit code.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <filesystem>
#include <fstream>
#include <string>

#include "nlohmann/json.hpp"

namespace {

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

CommandResult Alphactl(const std::string& args) {
  const std::string dir = std::filesystem::temp_directory_path() / ("alphactl_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string command =
      std::string(GALPHA_ALPHACTL) + " " + args + " >" + dir + "/out 2>" + dir + "/err";
  const int status = std::system(command.c_str());
  CommandResult run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = Slurp(dir + "/out");
  run.err = Slurp(dir + "/err");
  std::filesystem::remove_all(dir);
  return run;
}

std::string WriteFile(const std::string& name, const std::string& text) {
  const std::string path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path;
}

TEST(AlphactlTest, TriangulatesACsvAndPrintsOneJsonObject) {
  // A unit square with its centre: 4 triangles, 8 edges, 4 hull edges; one duplicate.
  const std::string path = WriteFile("alphactl_square.csv", "x,y\n0,0\n1,0\n0,1\n1,1\n0.5,0.5\n1,1\n");
  const CommandResult run = Alphactl("triangulate " + Quote(path) + " --backend=cpu");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["file"], path);
  EXPECT_EQ(j["points"], 6);
  EXPECT_EQ(j["distinct_points"], 5);
  EXPECT_EQ(j["duplicates"], 1);
  EXPECT_EQ(j["triangles"], 4);
  EXPECT_EQ(j["edges"], 8);
  EXPECT_EQ(j["hull_edges"], 4);
  EXPECT_EQ(j["backend"], "cpu");
  EXPECT_GT(j["peak_memory_bytes"].get<double>(), 0);
  EXPECT_TRUE(j["stage_ms"].contains("insert_and_flip"));
  std::filesystem::remove(path);
}

TEST(AlphactlTest, FileNamesAreEscapedInTheJson) {
  const std::string path = WriteFile("alphactl_we\"ird\\name.csv", "0 0\n1 0\n0 1\n");
  const CommandResult run = Alphactl("triangulate " + Quote(path) + " --backend=cpu");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out)["file"], path);
  std::filesystem::remove(path);
}

TEST(AlphactlTest, ErrorsAreOneLineAndANonZeroExit) {
  const CommandResult missing = Alphactl("triangulate /nonexistent/points.csv");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_TRUE(missing.out.empty());
  EXPECT_NE(missing.err.find("does not exist"), std::string::npos) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;

  const std::string bad = WriteFile("alphactl_bad.csv", "1,2\n3,oops\n");
  const CommandResult parse = Alphactl("triangulate " + Quote(bad));
  EXPECT_NE(parse.exit_code, 0);
  EXPECT_NE(parse.err.find(":2:"), std::string::npos) << parse.err;
  EXPECT_EQ(std::count(parse.err.begin(), parse.err.end(), '\n'), 1) << parse.err;
  std::filesystem::remove(bad);

  const std::string nan = WriteFile("alphactl_nan.csv", "0,0\n1,nan\n");
  const CommandResult invalid = Alphactl("triangulate " + Quote(nan) + " --backend=cpu");
  EXPECT_NE(invalid.exit_code, 0);
  EXPECT_NE(invalid.err.find("point 1"), std::string::npos) << invalid.err;
  std::filesystem::remove(nan);

  const CommandResult option = Alphactl("triangulate x.csv --backend=tpu");
  EXPECT_NE(option.exit_code, 0);
  EXPECT_NE(option.err.find("tpu"), std::string::npos) << option.err;
}

}  // namespace
