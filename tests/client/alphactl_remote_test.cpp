// alphactl --server against the real galpha_server process: a server started as users start it
// (its "listening on port N" line read from its stdout), every query command's output compared
// byte for byte with the local command's, the upload skipped when the server holds the file,
// errors as one line with the local exit codes, and the process's drain on SIGTERM.
#include <gtest/gtest.h>

#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX kill and signal numbers
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/types/span.h"
#include "tests/support/data_files.hpp"
#include "tests/support/server_process.hpp"

namespace {

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

CommandResult Alphactl(const std::string& args, const std::string& environment = "") {
  const std::string dir = std::filesystem::temp_directory_path() / ("alphactl_remote_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string command = environment + " " + GALPHA_ALPHACTL + " " + args + " >" + dir + "/out 2>" + dir + "/err";
  const int status = std::system(command.c_str());
  CommandResult run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = Slurp(dir + "/out");
  run.err = Slurp(dir + "/err");
  std::filesystem::remove_all(dir);
  return run;
}

using galpha::testing::ServerProcess;
constexpr char kServerFlags[] = "--drain_notice_ms 200";

/// Each of `commands` on `file` (then `options`) prints the same locally and against `server`.
void ExpectRemotePrintsAsLocal(const ServerProcess& server, const std::string& file,
                               absl::Span<const char* const> commands, const std::string& options = "") {
  for (const char* command : commands) {
    SCOPED_TRACE(command);
    const std::string args = absl::StrCat(command, " ", file, options);
    const CommandResult local = Alphactl(args);
    const CommandResult remote = Alphactl(args + " --server " + server.address());
    EXPECT_EQ(local.exit_code, 0) << local.err;
    EXPECT_EQ(remote.exit_code, 0) << remote.err;
    EXPECT_FALSE(local.out.empty());
    EXPECT_EQ(remote.out, local.out);
  }
}

TEST(AlphactlRemoteTest, EveryQueryCommandPrintsWhatTheLocalOnePrints) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  const char* commands[] = {
      "spectrum",
      "classify --rank 100",
      "classify --alpha-sq 2.5e-5 --mode regularized --vertex-rule cgal",
      "summary --alpha 0.004",
      "summary --rank 0",
      "summary --ratio 0.5 --mode regularized",
      "shape --ratio 0.8 --format wkt",
      "shape --rank 300 --format geojson",
      "shape --alpha-sq 1e-4 --format wkt --mode regularized",
      "shape --rank 50 --format svg",
      "masterlist --rank 77",
      "optimal --components 3",
      "persistence",
      "persistence --dimension 1 --min-persistence 1e-6 --format csv",
      "persistence --format json --dimension 0",
      "persistence --format svg",
      "holes --rank 3500",
      "holes --rank 3500 --format geojson --min-area 0",
  };
  ExpectRemotePrintsAsLocal(server, file, commands);
  // bench runs on the server: its table names the server's backend and the RPC's time.
  const CommandResult bench = Alphactl("bench " + file + " --server " + server.address());
  EXPECT_EQ(bench.exit_code, 0) << bench.err;
  EXPECT_NE(bench.out.find("rpc_total"), std::string::npos) << bench.out;
  EXPECT_NE(bench.out.find("backend"), std::string::npos);
}

#ifdef GALPHA_WITH_PROJ
// The GPS tracks are WGS84 longitudes and latitudes: with --crs the server holds their local
// projection (metres) and alphactl writes the geometry in the input's coordinates, as locally.
TEST(AlphactlRemoteTest, GeographicInputAnswersAsLocally) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  const char* commands[] = {
      "spectrum",
      "summary --ratio 0.5 --mode regularized",
      "shape --ratio 0.8 --format geojson",
      "shape --alpha 2000 --format wkt --mode general",
      "shape --rank 300 --format svg --min-hole-area 1e6",
      "holes --rank 3500 --format geojson",
      "holes --rank 3500",
  };
  ExpectRemotePrintsAsLocal(server, file, commands, " --crs EPSG:4326");
}
#endif

/// A GeoJSON FeatureCollection of `per_group` points around each of three centres, the property
/// "kind" naming the group ("b", "a", and none for the third), `spread` wide.
std::string GroupedGeoJson(double x0, double y0, double spread, int per_group) {
  std::mt19937_64 random(11);
  std::normal_distribution<double> normal(0.0, spread);
  const double centres[3][2] = {{x0, y0}, {x0 + 20 * spread, y0 + 5 * spread}, {x0 - 10 * spread, y0 + 15 * spread}};
  const char* kinds[3] = {R"({"kind":"b"})", R"({"kind":"a"})", R"({"other":1})"};
  std::string features;
  for (int i = 0; i < 3 * per_group; ++i) {
    const int g = i % 3;
    char point[96];
    std::snprintf(point, sizeof point, "[%.17g,%.17g]", centres[g][0] + normal(random), centres[g][1] + normal(random));
    features += absl::StrCat(i ? "," : "", R"({"type":"Feature","properties":)", kinds[g],
                             R"(,"geometry":{"type":"Point","coordinates":)", point, "}}");
  }
  return absl::StrCat(R"({"type":"FeatureCollection","features":[)", features, "]}");
}

// shape --group-by --server builds the groups in one BuildBatch call and prints what the local
// command prints, group for group.
TEST(AlphactlRemoteTest, GroupedShapesAnswerAsLocally) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file =
      std::filesystem::temp_directory_path() / ("alphactl_groups_" + std::to_string(getpid()) + ".geojson");
  std::ofstream(file) << GroupedGeoJson(0, 0, 1.0, 150);
  const char* commands[] = {
      "shape --ratio 0.7 --group-by kind --format geojson",
      "shape --ratio 0.7 --group-by kind --format wkt",
      "shape --rank 40 --group-by kind --format geojson --min-hole-area 0.5",
  };
  ExpectRemotePrintsAsLocal(server, file, commands, " --crs none");
  // A threshold one group cannot take is refused naming the group, with the local exit code.
  const CommandResult local = Alphactl("shape " + file + " --rank 100000 --group-by kind --format wkt --crs none");
  const CommandResult remote =
      Alphactl("shape " + file + " --rank 100000 --group-by kind --format wkt --crs none --server " + server.address());
  EXPECT_EQ(local.exit_code, 2) << local.err;
  EXPECT_EQ(remote.exit_code, local.exit_code) << remote.err;
  EXPECT_NE(remote.err.find("group 'b'"), std::string::npos) << remote.err;
#ifdef GALPHA_WITH_PROJ
  // Longitudes and latitudes (GeoJSON's own CRS): each group in its own local projection.
  std::ofstream(file) << GroupedGeoJson(14.1, 45.4, 0.001, 120);
  const char* geographic[] = {"shape --ratio 0.6 --group-by kind --format geojson",
                              "shape --alpha 30 --group-by kind --format wkt"};
  ExpectRemotePrintsAsLocal(server, file, geographic);
#endif
  std::filesystem::remove(file);
}

// Weighted points go up as (x, y, w) (BuildHeader.weighted), encoded or raw, and every answer is
// the local weighted family's: hidden points included, which the remote summary lists from the
// server's count and Classify at rank 0, duplicates of hidden points with them.
TEST(AlphactlRemoteTest, WeightedPointsAnswerAsLocally) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  // Disks of squared radius 0.6 to 0.79 on a perturbed unit grid, and in every third cell a point
  // of weight 0 at its centre: the corners' plane lifts the centre to about |c|^2 + 0.5 - 0.7,
  // under its own |c|^2, so it is hidden. The last lines repeat a hidden centre and a grid point,
  // add a light point next to a heavy one and a lighter point at a grid point's position (a
  // point of its own, not a duplicate: both hidden).
  const std::string file = std::filesystem::temp_directory_path() / "alphactl_remote_weighted.csv";
  {
    std::ofstream out(file);
    for (int i = 0; i < 20; ++i) {
      for (int j = 0; j < 20; ++j) {
        out << i + (i * j % 7) / 100.0 << ' ' << j + ((i + 2 * j) % 5) / 100.0 << ' '
            << 0.6 + ((i * 7 + j * 13) % 20) / 100.0 << '\n';
      }
    }
    for (int i = 0; i < 19; i += 3) {
      for (int j = 0; j < 19; j += 3) out << i + 0.5 << ' ' << j + 0.5 << " 0\n";
    }
    out << "3.5 6.5 0\n0 0 0.6\n5.05 5 0.5\n0 0 0.3\n";
  }
  const CommandResult local = Alphactl("summary " + file + " --rank 0 --backend=cpu --weights squared");
  ASSERT_EQ(local.exit_code, 0) << local.err;
  EXPECT_NE(local.out.find("\"hidden_points\":[400,"), std::string::npos) << local.out;  // not null, not []
  const char* commands[] = {
      "summary --rank 0",
      "summary --alpha-sq -0.5",
      "summary --rank 40 --mode regularized",
      "spectrum",
      "classify --rank 7",
      "shape --rank 30 --format wkt",
      "masterlist --rank 12",
      "optimal --components 1",
      "persistence",
  };
  ExpectRemotePrintsAsLocal(server, file, commands, " --weights squared");
  // Raw triples build the same family (the same handle: found, not rebuilt).
  const CommandResult raw =
      Alphactl("--encoding raw --server " + server.address() + " summary " + file + " --rank 0 --weights squared");
  EXPECT_EQ(raw.exit_code, 0) << raw.err;
  EXPECT_EQ(raw.out, local.out);
  // The same coordinates unweighted are another family: no hidden points.
  const CommandResult unweighted = Alphactl("--server " + server.address() + " summary " + file + " --rank 0");
  EXPECT_EQ(unweighted.exit_code, 0) << unweighted.err;
  EXPECT_NE(unweighted.out.find("\"hidden_points\":null"), std::string::npos) << unweighted.out;
  std::filesystem::remove(file);
}

// --server, like every global option, may come before the command (as in git and kubectl), and
// a pipe is read once and uploaded like a file.
TEST(AlphactlRemoteTest, ServerMayComeBeforeTheCommand) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  const CommandResult local = Alphactl("summary " + file + " --rank 40");
  const CommandResult before = Alphactl("--server " + server.address() + " summary " + file + " --rank 40");
  const CommandResult equals = Alphactl("--server=" + server.address() + " masterlist " + file + " --rank 7");
  ASSERT_EQ(local.exit_code, 0) << local.err;
  EXPECT_EQ(before.exit_code, 0) << before.err;
  EXPECT_EQ(before.out, local.out);
  EXPECT_EQ(equals.exit_code, 0) << equals.err;
  EXPECT_EQ(equals.out, Alphactl("masterlist " + file + " --rank 7").out);

  const CommandResult piped =
      Alphactl("--server " + server.address() + " bench - --repeat 2", "printf '0 0\\n1 0\\n0 1\\n1 1\\n' |");
  EXPECT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_NE(piped.out.find("# -: 4 points, 4 distinct, best of 2 builds"), std::string::npos) << piped.out;

  const CommandResult twice =
      Alphactl("--server " + server.address() + " spectrum " + file + " --server " + server.address());
  EXPECT_EQ(twice.exit_code, 2);
  EXPECT_NE(twice.err.find("--server given twice"), std::string::npos) << twice.err;
}

// alphactl sends the smallest encoding on its own (EncodedPointChunk; docs/design.md, "Wire
// encodings of points"): Autzen's LiDAR, 0.01 ft integers, goes up in under 4 bytes a point (raw
// doubles would be 16), and the remote answer is the local one.
TEST(AlphactlRemoteTest, UploadsInTheSmallestEncoding) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/lidar_autzen.bin";
  const CommandResult local = Alphactl("summary " + file + " --rank 1000");
  const CommandResult remote = Alphactl("--server " + server.address() + " summary " + file + " --rank 1000");
  ASSERT_EQ(remote.exit_code, 0) << remote.err;
  EXPECT_EQ(remote.out, local.out);
  // "alphactl: family built on the server (0.52 s; 214512 bytes of points sent, 1.95 per point)"
  const size_t at = remote.err.find(" bytes of points sent, ");
  ASSERT_NE(at, std::string::npos) << remote.err;
  const double per_point =
      std::strtod(remote.err.c_str() + at + std::string(" bytes of points sent, ").size(), nullptr);
  EXPECT_GT(per_point, 0.5) << remote.err;
  EXPECT_LE(per_point, 4.0) << remote.err;
}

// --encoding raw sends 16-byte doubles (what servers older than encoded chunks accept): the same
// answers, 16 bytes a point; the option needs --server and a known value.
TEST(AlphactlRemoteTest, RawEncodingSendsDoubles) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/lidar_autzen.bin";
  const CommandResult local = Alphactl("summary " + file + " --rank 1000");
  const CommandResult remote =
      Alphactl("--encoding raw --server " + server.address() + " summary " + file + " --rank 1000");
  ASSERT_EQ(remote.exit_code, 0) << remote.err;
  EXPECT_EQ(remote.out, local.out);
  EXPECT_NE(remote.err.find(" bytes of points sent, 16.00 per point"), std::string::npos) << remote.err;
  const CommandResult unknown =
      Alphactl("--server " + server.address() + " summary " + file + " --rank 1 --encoding zip");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("unknown --encoding 'zip' (expected auto or raw)"), std::string::npos) << unknown.err;
  const CommandResult local_encoding = Alphactl("summary " + file + " --rank 1 --encoding raw");
  EXPECT_EQ(local_encoding.exit_code, 2);
  EXPECT_NE(local_encoding.err.find("--encoding needs --server"), std::string::npos) << local_encoding.err;
}

// classify's --answer-encoding changes what crosses the wire (the default is delta), never the
// output; it is refused without --server and with a value it does not know.
TEST(AlphactlRemoteTest, EveryAnswerEncodingPrintsWhatTheLocalClassifyPrints) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/lidar_autzen_ground.bin";
  const char* commands[] = {
      "classify --rank 2000 --answer-encoding raw",
      "classify --rank 2000 --answer-encoding delta",
      "classify --rank 2000 --answer-encoding zstd",
      "classify --alpha-sq 30 --mode regularized --answer-encoding zstd",
  };
  for (const char* command : commands) {
    SCOPED_TRACE(command);
    const std::string local_args =
        absl::StrCat(std::string(command).substr(0, std::string(command).find(" --answer-encoding")), " ", file);
    const CommandResult local = Alphactl(local_args);
    const CommandResult remote = Alphactl(absl::StrCat(command, " ", file, " --server ", server.address()));
    EXPECT_EQ(local.exit_code, 0) << local.err;
    EXPECT_EQ(remote.exit_code, 0) << remote.err;
    EXPECT_GT(local.out.size(), 100000u);
    EXPECT_EQ(remote.out, local.out);
  }
  const CommandResult local_only = Alphactl("classify " + file + " --rank 1 --answer-encoding zstd");
  EXPECT_EQ(local_only.exit_code, 2);
  EXPECT_NE(local_only.err.find("--answer-encoding needs --server"), std::string::npos) << local_only.err;
  const CommandResult unknown =
      Alphactl("classify " + file + " --rank 1 --answer-encoding gzip --server " + server.address());
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("unknown --answer-encoding 'gzip' (expected raw, delta or zstd)"), std::string::npos)
      << unknown.err;
}

TEST(AlphactlRemoteTest, ErrorsKeepTheLocalExitCodes) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  const CommandResult local = Alphactl("masterlist " + file + " --rank 999999999");
  const CommandResult remote = Alphactl("masterlist " + file + " --rank 999999999 --server " + server.address());
  EXPECT_EQ(local.exit_code, 2);
  EXPECT_EQ(remote.exit_code, 2);
  EXPECT_EQ(remote.err, local.err);

  const CommandResult backend = Alphactl("spectrum " + file + " --backend cpu --server " + server.address());
  EXPECT_EQ(backend.exit_code, 2);
  EXPECT_NE(backend.err.find("--backend applies to local builds"), std::string::npos) << backend.err;

  const CommandResult unreachable = Alphactl("spectrum " + file + " --server 127.0.0.1:1");
  EXPECT_EQ(unreachable.exit_code, 1);
  EXPECT_EQ(std::count(unreachable.err.begin(), unreachable.err.end(), '\n'), 1) << unreachable.err;
  EXPECT_EQ(unreachable.err.rfind("alphactl: server 127.0.0.1:1: ", 0), 0u) << unreachable.err;
}

TEST(AlphactlRemoteTest, TokensComeFromTheEnvironment) {
  const std::string tokens = std::filesystem::temp_directory_path() / ("galpha_tokens_" + std::to_string(getpid()));
  std::ofstream(tokens) << "# test tokens\nsecret-1 team-one\n";
  ServerProcess server(GALPHA_SERVER, std::string(kServerFlags) + " --token_file " + tokens);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  const CommandResult without = Alphactl("summary --rank 1 " + file + " --server " + server.address());
  EXPECT_EQ(without.exit_code, 1);
  EXPECT_NE(without.err.find("Bearer TOKEN"), std::string::npos) << without.err;
  const CommandResult with =
      Alphactl("summary --rank 1 " + file + " --server " + server.address(), "GALPHA_TOKEN=secret-1");
  EXPECT_EQ(with.exit_code, 0) << with.err;
  std::filesystem::remove(tokens);
}

TEST(AlphactlRemoteTest, SigtermDrainsAndExitsCleanly) {
  ServerProcess server(GALPHA_SERVER, kServerFlags);
  ASSERT_GT(server.port(), 0) << server.log();
  // The container image's health check: exit 0 while the API is SERVING.
  const std::string check = std::string(GALPHA_SERVER) + " --health_check " + server.address() + " >/dev/null 2>&1";
  EXPECT_EQ(std::system(check.c_str()), 0);
  const std::string nowhere = std::string(GALPHA_SERVER) + " --health_check 127.0.0.1:1 >/dev/null 2>&1";
  EXPECT_NE(std::system(nowhere.c_str()), 0);
  EXPECT_EQ(server.Signal(SIGTERM, 30), 0) << server.log();
  const std::string log = server.log();
  EXPECT_NE(log.find("draining"), std::string::npos) << log;
  EXPECT_NE(log.find("stopped"), std::string::npos) << log;
}

}  // namespace
