// The untrusted-path rule for RIB files (docs/rib.md, "Untrusted scene
// files"): ReadArchive and texture names resolve inside the scene's folder and
// the allowed folders only, after "..", "." and symbolic links; the searchpath
// option chooses where names are looked up but never widens that.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>

#include "io/image_io.h"
#include "rib/rib_reader.h"

namespace {

namespace fs = std::filesystem;

void write_file(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

// A folder tree per test: T/scene (the scene's folder), T/outside.rib beside
// it, T/scene2 (a sibling whose name starts like it), T/other with a texture.
class UntrustedPaths : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    top_ = fs::path(::testing::TempDir()) / ("untrusted_paths_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(top_);
    fs::create_directories(top_);
    top_ = fs::canonical(top_);
    scene_ = top_ / "scene";
    write_file(scene_ / "inside.rib", "Format 11 11 1\n");
    write_file(top_ / "outside.rib", "Format 22 22 1\n");
    write_file(top_ / "scene2" / "x.rib", "Format 33 33 1\n");
    write_file(scene_ / "parts" / "p.rib", "Format 44 44 1\n");
    write_file(scene_ / "more" / "p.rib", "Format 55 55 1\n");
    write_file(scene_ / "more" / "q.rib", "Format 66 66 1\n");
    fs::create_symlink(top_ / "outside.rib", scene_ / "link.rib");
    fs::create_directories(top_ / "other");
    fs::create_directory_symlink(top_ / "other", scene_ / "linkdir");
    mp::RenderResult png;
    png.width = 1, png.height = 1;
    png.rgba = {1.0f, 0.0f, 0.0f, 1.0f};
    fs::create_directories(scene_ / "textures");
    mp::write_image((top_ / "other" / "tex.png").string(), png);
    mp::write_image((scene_ / "tex.png").string(), png);
    mp::write_image((scene_ / "textures" / "t.png").string(), png);
  }
  void TearDown() override { fs::remove_all(top_); }

  // Reads T/scene/main.rib holding `text`.
  mp::RibResult read(const std::string& text, const mp::RibReadOptions& options = {}) {
    write_file(scene_ / "main.rib", text);
    return mp::read_rib_file((scene_ / "main.rib").string(), options);
  }
  // The RibError message for T/scene/main.rib holding `text` ("" if none).
  std::string error(const std::string& text, const mp::RibReadOptions& options = {}) {
    try {
      read(text, options);
    } catch (const mp::RibError& e) {
      return e.what();
    }
    return "";
  }
  // The refusal message for `request` naming `name` that resolves to `resolved`.
  std::string refusal(int line, const std::string& request, const std::string& name, const fs::path& resolved) {
    return (scene_ / "main.rib").string() + ":" + std::to_string(line) + ": " + request + " \"" + name +
           "\" refused: " + resolved.string() + " is outside the scene's folder " + scene_.string() +
           " and the allowed folders (allow it with --allow-path DIR or --allow-any-path)";
  }

  fs::path top_, scene_;
};

TEST_F(UntrustedPaths, ArchivesOutsideTheScenesFolderAreRefused) {
  EXPECT_EQ(error("ReadArchive \"../outside.rib\"\n"),
            refusal(1, "ReadArchive", "../outside.rib", top_ / "outside.rib"));
  EXPECT_EQ(error("\nReadArchive \"/etc/passwd\"\n"), refusal(2, "ReadArchive", "/etc/passwd", "/etc/passwd"));
  // A symbolic link in the scene's folder pointing out of it.
  EXPECT_EQ(error("ReadArchive \"link.rib\"\n"), refusal(1, "ReadArchive", "link.rib", top_ / "outside.rib"));
  // A folder whose name merely starts with the scene folder's.
  EXPECT_EQ(error("ReadArchive \"../scene2/x.rib\"\n"),
            refusal(1, "ReadArchive", "../scene2/x.rib", top_ / "scene2" / "x.rib"));
  // A missing file outside is refused too, not reported missing.
  EXPECT_EQ(error("ReadArchive \"../missing.rib\"\n"),
            refusal(1, "ReadArchive", "../missing.rib", top_ / "missing.rib"));
  // From a nested archive, relative to that archive's own folder.
  write_file(scene_ / "sub" / "nested.rib", "ReadArchive \"../../outside.rib\"\n");
  const std::string nested = error("ReadArchive \"sub/nested.rib\"\n");
  EXPECT_EQ(nested.rfind((scene_ / "sub" / "nested.rib").string() + ":1: ReadArchive \"../../outside.rib\" refused: " +
                             (top_ / "outside.rib").string() + " is outside",
                         0),
            0u)
      << nested;
}

TEST_F(UntrustedPaths, ArchivesInsideTheScenesFolderAreRead) {
  EXPECT_EQ(read("ReadArchive \"inside.rib\"\n").scene.settings.width, 11);
  // An absolute path inside the scene's folder.
  EXPECT_EQ(read("ReadArchive \"" + (scene_ / "inside.rib").string() + "\"\n").scene.settings.width, 11);
  // ".." that stays inside.
  EXPECT_EQ(read("ReadArchive \"parts/../inside.rib\"\n").scene.settings.width, 11);
  // A missing file inside is reported missing.
  const std::string missing = error("ReadArchive \"nothing.rib\"\n");
  EXPECT_NE(missing.find(":1: ReadArchive: cannot read \"" + (scene_ / "nothing.rib").string() + "\": No such file"),
            std::string::npos)
      << missing;
}

TEST_F(UntrustedPaths, AllowedRootsAndAllowAnyPath) {
  mp::RibReadOptions roots;
  roots.allowed_roots = {top_.string()};
  EXPECT_EQ(read("ReadArchive \"../outside.rib\"\n", roots).scene.settings.width, 22);
  EXPECT_EQ(read("ReadArchive \"link.rib\"\n", roots).scene.settings.width, 22);
  // Roots are compared canonically as well: a root given through a link.
  mp::RibReadOptions via_link;
  via_link.allowed_roots = {(scene_ / "linkdir").string()};
  EXPECT_EQ(error("Option \"micropoly\" \"string imagefile\" \"linkdir/tex.png\"\n", via_link), "");
  EXPECT_NE(error("ReadArchive \"../outside.rib\"\n", via_link), "");

  mp::RibReadOptions any;
  any.allow_any_path = true;
  EXPECT_EQ(read("ReadArchive \"../outside.rib\"\n", any).scene.settings.width, 22);
  // Any path is read as such: a device is still not a regular file.
  const std::string dev = error("ReadArchive \"/dev/zero\"\n", any);
  EXPECT_NE(dev.find(":1: ReadArchive: cannot read \"/dev/zero\": not a regular file"), std::string::npos) << dev;
}

TEST_F(UntrustedPaths, SearchPathChoosesWhereNamesAreLookedUp) {
  // Relative entries are relative to the file holding the option; the first
  // folder holding the name wins.
  EXPECT_EQ(read("Option \"searchpath\" \"string archive\" \"parts:more\"\nReadArchive \"p.rib\"\n").scene.settings.width,
            44);
  EXPECT_EQ(read("Option \"searchpath\" \"string archive\" \"more:parts\"\nReadArchive \"p.rib\"\n").scene.settings.width,
            55);
  // '&' is the previous value, '@' the default (the requesting file's folder);
  // a bare "archive" token (RenderMan's predeclared form) works the same.
  EXPECT_EQ(read("Option \"searchpath\" \"string archive\" \"parts\"\n"
                 "Option \"searchpath\" \"archive\" \"&:more\"\nReadArchive \"q.rib\"\n")
                .scene.settings.width,
            66);
  EXPECT_EQ(read("Option \"searchpath\" \"string archive\" \"parts:@\"\nReadArchive \"inside.rib\"\n").scene.settings.width,
            11);
  // Without '@' the scene's folder is no longer searched.
  EXPECT_NE(error("Option \"searchpath\" \"string archive\" \"parts\"\nReadArchive \"inside.rib\"\n")
                .find("ReadArchive: cannot read \"" + (scene_ / "parts" / "inside.rib").string() + "\""),
            std::string::npos);
  // The texture search path is separate from the archive one.
  EXPECT_EQ(error("Option \"searchpath\" \"string texture\" \"textures\"\n"
                  "Option \"micropoly\" \"string imagefile\" \"t.png\"\n"),
            "");
  EXPECT_NE(error("Option \"searchpath\" \"string archive\" \"textures\"\n"
                  "Option \"micropoly\" \"string imagefile\" \"t.png\"\n"),
            "");
}

TEST_F(UntrustedPaths, SearchPathEntriesDoNotWidenTheAllowedFolders) {
  EXPECT_EQ(error("Option \"searchpath\" \"string archive\" \"/:&\"\nReadArchive \"etc/passwd\"\n"),
            refusal(2, "ReadArchive", "etc/passwd", "/etc/passwd"));
  EXPECT_EQ(error("Option \"searchpath\" \"string archive\" \"..\"\nReadArchive \"outside.rib\"\n"),
            refusal(2, "ReadArchive", "outside.rib", top_ / "outside.rib"));
  // An entry outside that does not hold the name is passed over.
  EXPECT_EQ(read("Option \"searchpath\" \"string archive\" \"/:@\"\nReadArchive \"inside.rib\"\n").scene.settings.width,
            11);
  // The user's roots do allow it.
  mp::RibReadOptions roots;
  roots.allowed_roots = {top_.string()};
  EXPECT_EQ(read("Option \"searchpath\" \"string archive\" \"..\"\nReadArchive \"outside.rib\"\n", roots)
                .scene.settings.width,
            22);
  // A malformed value is an error at its line.
  EXPECT_NE(error("Option \"searchpath\" \"archive\" 1\n").find("main.rib:1: "), std::string::npos);
}

TEST_F(UntrustedPaths, TexturesFollowTheSameRule) {
  const std::string image = "Option \"micropoly\" \"imagefile\"";
  EXPECT_EQ(error("Option \"micropoly\" \"string imagefile\" \"../other/tex.png\"\n"),
            refusal(1, image, "../other/tex.png", top_ / "other" / "tex.png"));
  EXPECT_EQ(error("Option \"micropoly\" \"string imagefile\" \"linkdir/tex.png\"\n"),
            refusal(1, image, "linkdir/tex.png", top_ / "other" / "tex.png"));
  EXPECT_EQ(error("Option \"micropoly\" \"string imagefile\" \"/etc/passwd.png\"\n"),
            refusal(1, image, "/etc/passwd.png", "/etc/passwd.png"));
  EXPECT_EQ(error("WorldBegin\nLightSource \"micropoly_environmentlight\" 1 \"string mapname\" \"../other/tex.png\"\n"
                  "WorldEnd\n"),
            refusal(2, "LightSource \"micropoly_environmentlight\" \"mapname\"", "../other/tex.png",
                    top_ / "other" / "tex.png"));
  const mp::RibResult r = read("Option \"micropoly\" \"string imagefile\" \"tex.png\"\n"
                               "Option \"micropoly\" \"string imagefile\" \"" + (scene_ / "tex.png").string() + "\"\n");
  EXPECT_EQ(r.scene.images.size(), 2u);
  mp::RibReadOptions any;
  any.allow_any_path = true;
  EXPECT_EQ(read("Option \"micropoly\" \"string imagefile\" \"linkdir/tex.png\"\n", any).scene.images.size(), 1u);
}

TEST_F(UntrustedPaths, ReadRibStringUsesItsBaseDirAsTheScenesFolder) {
  try {
    mp::read_rib_string("ReadArchive \"../outside.rib\"\n", "text.rib", scene_.string());
    FAIL() << "no refusal";
  } catch (const mp::RibError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("text.rib:1: ReadArchive \"../outside.rib\" refused: ", 0), 0u) << e.what();
  }
  EXPECT_EQ(mp::read_rib_string("ReadArchive \"inside.rib\"\n", "text.rib", scene_.string()).scene.settings.width, 11);
}

// micropoly-render as a subprocess: exit status and the first line of its
// output (stdout and stderr together).
struct CliRun {
  int status = -1;
  std::string output;
};

CliRun run_cli(const std::string& arguments) {
  CliRun run;
  FILE* pipe = ::popen((std::string(MICROPOLY_CLI) + " " + arguments + " 2>&1").c_str(), "r");
  if (!pipe) return run;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) run.output += buf;
  const int status = ::pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return run;
}

TEST_F(UntrustedPaths, CliRefusesAndItsFlagsAllow) {
  write_file(scene_ / "main.rib", "WorldBegin\nReadArchive \"../outside.rib\"\nWorldEnd\n");
  // outside.rib is malformed on purpose: once it is allowed, reading it fails
  // on its own contents, which shows it was read without rendering anything.
  write_file(top_ / "outside.rib", "Format 1\n");
  const std::string scene = (scene_ / "main.rib").string(), out = (top_ / "out.png").string();
  const CliRun refused = run_cli(scene + " -o " + out);
  EXPECT_EQ(refused.status, 2);
  EXPECT_EQ(refused.output, "micropoly-render: " + refusal(2, "ReadArchive", "../outside.rib", top_ / "outside.rib") + "\n");
  for (const std::string& flags : {std::string("--allow-any-path"), "--allow-path " + top_.string()}) {
    const CliRun allowed = run_cli(scene + " -o " + out + " " + flags);
    EXPECT_EQ(allowed.status, 2) << flags;
    EXPECT_EQ(allowed.output.rfind("micropoly-render: " + (scene_ / "../outside.rib").string() + ":1: Format:", 0), 0u)
        << flags << ": " << allowed.output;
  }
  const CliRun help = run_cli("--help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.output.find("[--allow-path DIR]... [--allow-any-path]"), std::string::npos);
  EXPECT_EQ(run_cli(scene + " --allow-path").status, 2);  // needs a value
}

// The crafted files in tests/scenes/untrusted: each is refused with its reason.
TEST(UntrustedScenes, CraftedFilesAreRefused) {
  const std::string dir = std::string(MICROPOLY_TEST_SCENES) + "/untrusted/";
  auto message = [&](const std::string& file) {
    try {
      mp::read_rib_file(dir + file);
    } catch (const mp::RibError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const struct {
    const char* file;
    const char* reason;
  } cases[] = {
      {"archive_escape.rib", ":3: ReadArchive \"../../../../../../../../etc/passwd\" refused: /etc/passwd is outside"},
      {"searchpath_root.rib", ":4: ReadArchive \"etc/passwd\" refused: /etc/passwd is outside"},
      {"texture_escape.rib", ":2: Option \"micropoly\" \"imagefile\" \"/usr/share/pixmaps/debian-logo.png\" refused"},
      {"png_bomb.rib", "its header claims 10000x10000 pixels, more than 69 bytes of deflate data can hold"},
      {"exr_bomb.rib", "its header claims 10000x10000 pixels, more than 5347 bytes of ZIP data can hold"},
      {"nvertices_bomb.rib", ":3: PointsPolygons: vertices has 3 entries but nvertices adds up to 2147483647"},
  };
  for (const auto& c : cases) {
    const std::string m = message(c.file);
    EXPECT_NE(m.find(c.reason), std::string::npos) << c.file << ": " << m;
  }
}

}  // namespace

namespace {

// Material and world programs from a scene file: no directive the compiler
// runs on the host, no inline assembly (rib/rib_program_check.h).
std::string program_error(const std::string& program, bool allow_any = false) {
  std::string quoted;
  for (char c : program) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  mp::RibReadOptions options;
  options.allow_any_path = allow_any;
  try {
    mp::read_rib_string("WorldBegin\nAttribute \"micropoly\" \"integer material\" 1\n  \"string program\" \"" + quoted +
                            "\"\nWorldEnd\n",
                        "prog.rib", ".", options);
  } catch (const mp::RibError& e) {
    return e.what();
  }
  return "";
}

const std::string kSurface = "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {}\n";

TEST(UntrustedPrograms, DirectivesThatReadFilesAreRefused) {
  EXPECT_EQ(program_error("#include </etc/passwd>\n" + kSurface),
            "prog.rib:3: Attribute \"micropoly\" \"program\" refused: the directive #include is not accepted (the "
            "compiler would run it on the host); a scene file's program may not reach beyond the device (allow it "
            "with --allow-any-path)");
  for (const std::string& sneaky :
       {"  #  include \"/etc/passwd\"\n", "%:include </etc/passwd>\n", "?\?=include </etc/passwd>\n",
        "#inc\\\nlude </etc/passwd>\n", "/* a\n comment */ # /**/ include </etc/passwd>\n", "#include_next <x>\n",
        "#import <x>\n", "#embed </etc/passwd>\n", "#pragma clang __debug crash\n", "#pragma GCC dependency \"x\"\n"})
    EXPECT_NE(program_error(sneaky + kSurface).find("refused: the directive #"), std::string::npos) << sneaky;
  // The form the kernel assembler resolves from embedded headers, and the
  // directives node programs use, are accepted.
  EXPECT_EQ(program_error("#include \"textures/mp_noise.h\"\n#define MP_NODE_USES_NEIGHBOURS 1\n#if 1\n#endif\n"
                          "#pragma OPENCL EXTENSION cl_khr_fp16 : enable\n" + kSurface),
            "");
  // Inside strings and comments nothing is a directive.
  EXPECT_EQ(program_error("// #include <x>\nconstant char* t = \"#include <x>\";\n" + kSurface), "");
}

TEST(UntrustedPrograms, InlineAssemblyAndPastingAreRefused) {
  EXPECT_NE(program_error("void f(void) { __asm__ volatile(\"nop\"); }\n" + kSurface)
                .find("refused: inline assembly (__asm__) would run as native code on a CPU device"),
            std::string::npos);
  EXPECT_NE(program_error("#define A asm\n" + kSurface).find("inline assembly (asm)"), std::string::npos);
  EXPECT_NE(program_error("#define C(a, b) a##b\n" + kSurface).find("token pasting"), std::string::npos);
  EXPECT_NE(program_error("_Pragma(\"clang __debug crash\")\n" + kSurface).find("the _Pragma operator"),
            std::string::npos);
  // The world program is checked the same way.
  const std::string world = [] {
    try {
      mp::read_rib_string("WorldBegin\nLightSource \"micropoly_environmentlight\" 1 \"string program\" "
                          "\"void f(void) { asm(\\\"nop\\\"); }\"\nWorldEnd\n",
                          "world.rib");
    } catch (const mp::RibError& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_EQ(world.rfind("world.rib:2: LightSource \"micropoly_environmentlight\" \"program\" refused: inline assembly", 0),
            0u)
      << world;
  // A trusted file (any path allowed) is taken as it is.
  EXPECT_EQ(program_error("#include </etc/passwd>\n" + kSurface, true), "");
}

}  // namespace
