// The `limn` command line without HTTP: `limn render REQUEST.json --out DIR`, its errors, and
// the help and version texts.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/integration/http_client.h"
#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exitCode = -1;
  std::string out, err;
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Runs `limn ARGS` (ARGS already shell-quoted) and collects its exit status and output.
CliRun runLimn(const std::string& args) {
  fs::path dir = fs::temp_directory_path() / ("limn-cli-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string command = std::string("'") + limnBinary() + "' " + args + " >'" +
                        (dir / "out").string() + "' 2>'" + (dir / "err").string() + "'";
  int status = std::system(command.c_str());
  CliRun run;
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = slurp(dir / "out");
  run.err = slurp(dir / "err");
  fs::remove_all(dir);
  return run;
}

bool isPng(const fs::path& path) {
  std::string bytes = slurp(path);
  return bytes.size() > 8 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("limn-cli-test-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const std::string& text) {
    fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  fs::path dir_;
};

TEST_F(CliTest, RenderWritesTheAnswerAndEachImage) {
  fs::path request = write("cube.json", R"({
    "mesh": {"format": "obj", "data": "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\nf 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n"},
    "camera": {"width": 48, "height": 48},
    "method": "uniform", "params": {"level": 1},
    "outputs": ["color", "mask"],
    "reference": true
  })");
  fs::path out = dir_ / "out";
  CliRun run = runLimn("render '" + request.string() + "' --out '" + out.string() + "'");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(slurp(out / "response.json").find("\"images\""), std::string::npos);
  for (const char* name : {"color.png", "mask.png", "reference_color.png", "reference_mask.png"}) {
    EXPECT_TRUE(isPng(out / name)) << name;
  }
  EXPECT_FALSE(fs::exists(out / "depth.png")) << "only the requested passes are written";
}

TEST_F(CliTest, ABadRequestExits2WithItsJsonError) {
  fs::path request =
      write("bad.json", R"({"mesh": {"format": "obj", "data": "v 0 0 0\nf 1 2 3\n"}})");
  CliRun run = runLimn("render '" + request.string() + "' --out '" + (dir_ / "out").string() + "'");
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.err.find("\"code\":\"invalid_mesh\""), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "response.json"));

  CliRun notJson = runLimn("render '" + write("x.json", "{").string() + "' --out '" +
                           (dir_ / "out").string() + "'");
  EXPECT_EQ(notJson.exitCode, 2);
  EXPECT_NE(notJson.err.find("invalid_json"), std::string::npos) << notJson.err;
}

TEST_F(CliTest, UsageErrorsExit1) {
  EXPECT_EQ(runLimn("").exitCode, 1);
  EXPECT_EQ(runLimn("frobnicate").exitCode, 1);
  EXPECT_EQ(runLimn("render").exitCode, 1);
  EXPECT_EQ(runLimn("render '" + (dir_ / "missing.json").string() + "' --out x").exitCode, 1);
  EXPECT_EQ(runLimn("serve --listen nonsense").exitCode, 1);
  CliRun badConfig =
      runLimn("serve --config '" + write("c.json", R"({"wrokers": 2})").string() + "'");
  EXPECT_EQ(badConfig.exitCode, 1);
  EXPECT_NE(badConfig.err.find("wrokers"), std::string::npos) << badConfig.err;
}

// Sets an environment variable for one scope (the servers a test starts inherit it).
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const std::string& value) : name_(name) {
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnvironment() { ::unsetenv(name_); }
  ScopedEnvironment(const ScopedEnvironment&) = delete;
  ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

 private:
  const char* name_;
};

// What a container image relies on: LIMN_CONFIG names the file and LIMN_LISTEN the address
// when the command line does not, and the command line wins when it does.
TEST_F(CliTest, ServeTakesItsConfigurationAndAddressFromTheEnvironment) {
  ScopedEnvironment config("LIMN_CONFIG",
                           write("env.json", R"({"workers": 1, "queueDepth": 3})").string());
  // Another loopback address than the harness's 127.0.0.1, so that it is seen to be used.
  ScopedEnvironment listen("LIMN_LISTEN", "127.0.0.2:0");
  {
    ServerProcess server({}, std::chrono::seconds(60), /*loopbackListen=*/false);
    EXPECT_EQ(server.host(), "127.0.0.2");
    HttpClient client(server.port(), server.host());
    HttpResponse health = client.request("GET", "/healthz");
    EXPECT_EQ(health.status, 200);
    EXPECT_NE(health.body.find("\"workers\":1,"), std::string::npos) << health.body;
    EXPECT_NE(health.body.find("\"queueCapacity\":3,"), std::string::npos) << health.body;
    EXPECT_EQ(server.terminate(), 0);
  }
  {
    ServerProcess server({"--config", write("flag.json", R"({"workers": 2})").string()});
    EXPECT_EQ(server.host(), "127.0.0.1") << "--listen wins over LIMN_LISTEN";
    HttpResponse health = get(server.port(), "/healthz");
    EXPECT_NE(health.body.find("\"workers\":2,"), std::string::npos)
        << "--config wins over LIMN_CONFIG: " << health.body;
    EXPECT_EQ(server.terminate(), 0);
  }
}

TEST_F(CliTest, ABadEnvironmentIsAUsageErrorNamingTheVariable) {
  {
    ScopedEnvironment listen("LIMN_LISTEN", "nowhere");
    CliRun run = runLimn("serve");
    EXPECT_EQ(run.exitCode, 1);
    EXPECT_NE(run.err.find("LIMN_LISTEN wants HOST:PORT, got nowhere"), std::string::npos)
        << run.err;
  }
  ScopedEnvironment config("LIMN_CONFIG", (dir_ / "missing.json").string());
  CliRun run = runLimn("serve --listen 127.0.0.1:0");
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_NE(run.err.find("missing.json: cannot be opened"), std::string::npos) << run.err;
}

TEST_F(CliTest, HelpAndVersion) {
  CliRun help = runLimn("--help");
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.out.find("limn serve"), std::string::npos);
  EXPECT_NE(help.out.find("limn render"), std::string::npos);
  EXPECT_NE(help.out.find("LIMN_CONFIG"), std::string::npos);
  EXPECT_NE(help.out.find("LIMN_LISTEN"), std::string::npos);
  EXPECT_EQ(runLimn("help").out, help.out);
  CliRun version = runLimn("--version");
  EXPECT_EQ(version.exitCode, 0);
  EXPECT_EQ(version.out.rfind("limn ", 0), 0u);
}

}  // namespace
}  // namespace limn::testing
