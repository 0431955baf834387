// RIB reader on malformed and hostile input: every error is a RibError whose
// message starts with "FILE:LINE:" for the offending line; junk bytes either
// parse or throw RibError, never anything else (run under ASan/UBSan too).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "rib/rib_reader.h"

namespace {

const std::string kScenes = MICROPOLY_TEST_SCENES;

// Parses `text` and returns the RibError message ("" if it parsed).
std::string error_of(const std::string& text) {
  try {
    mp::read_rib_string(text, "bad.rib", kScenes);
  } catch (const mp::RibError& e) {
    return e.what();
  }
  return "";
}

void expect_error(const std::string& text, int line, const std::string& fragment) {
  const std::string msg = error_of(text);
  ASSERT_FALSE(msg.empty()) << "no error for:\n" << text;
  const std::string prefix = "bad.rib:" + std::to_string(line) + ": ";
  EXPECT_EQ(msg.rfind(prefix, 0), 0u) << "expected line " << line << ", got: " << msg;
  EXPECT_NE(msg.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << msg;
}

const char* kTri = "\"P\" [0 0 0 1 0 0 0 1 0]";

TEST(RibErrors, Lexical) {
  expect_error("WorldBegin\nPolygon \"P\" [0 0 0\n1 0 0\n", 2, "unterminated array");
  expect_error("WorldBegin\nPolygon \"P\" [0 0 0 1 0 0\nWorldEnd\n", 2, "unterminated array");
  expect_error("Format 1 1 1\nDisplay \"abc\nWorldBegin\nWorldEnd\n", 2, "unterminated string");
  expect_error("Display \"a\\", 1, "unterminated string");
  expect_error("WorldBegin\n]\n", 2, "']' without");
  expect_error("WorldBegin\nPolygon \"P\" [[0 0 0]]\n", 2, "nested arrays");
  expect_error("WorldBegin\nPolygon \"P\" [0 \"a\" 0]\n", 2, "mixes");
  expect_error("Format 1 1 1\nTranslate 1.2.3 0 0\n", 2, "malformed number '1.2.3'");
  expect_error("Translate 3x 0 0\n", 1, "malformed number");
  expect_error("Translate - 0 0\n", 1, "malformed number");
  expect_error("Translate 1e39 0 0\n", 1, "out of range");
  expect_error("Translate 1e400 0 0\n", 1, "out of range");
  // Just past the largest float's rounding range (FLT_MAX + 2^103 rounds to infinity).
  expect_error("Translate 3.40282357e38 0 0\n", 1, "out of range");
  expect_error("\n\nFormat { 1 1\n", 3, "unexpected character '{'");
  expect_error("\n42\nWorldBegin\n", 2, "expected a request name, found a number");
  expect_error("\"Format\" 1 1 1\n", 1, "expected a request name, found a string");
}

TEST(RibErrors, BinaryAndControlBytes) {
  expect_error("WorldBegin\n\x80\x01\x02", 2, "binary-encoded RIB");
  expect_error(std::string("Format 1 1 1\n\n\x01"), 3, "control character 0x01");
  expect_error(std::string("Format 1 1 1", 12) + std::string(1, '\0'), 1, "control character 0x00");
  expect_error("\x1f\x8b\x08\x00", 1, "gzip");
  expect_error("Display \"\xff\" \"file\" \"rgba\"\n", 1, "invalid UTF-8");
  expect_error("Display \"\xC0\xAF\" \"file\" \"rgba\"\n", 1, "invalid UTF-8");      // overlong
  expect_error("Display \"\xED\xA0\x80\" \"file\" \"rgba\"\n", 1, "invalid UTF-8");  // surrogate
  expect_error("# comment \xfe\nWorldBegin\n", 1, "invalid UTF-8 in a comment");
  expect_error("# comment \x07\n", 1, "control character 0x07 in a comment");
  expect_error("Display \"a\x1b\" \"file\" \"rgba\"\n", 1, "control character 0x1B in a string");
}

TEST(RibErrors, WrongArgumentTypesAndCounts) {
  expect_error("WorldBegin\nTranslate \"a\" 0 0\n", 2, "expected a number, found a string");
  expect_error("Format 640 \"x\" 1\n", 1, "Format: argument 2");
  expect_error("Format 640.5 480 1\n", 1, "expected an integer");
  expect_error("Format 0 480 1\n", 1, "expected an integer in [1,");
  expect_error("WorldBegin\nColor [1 0]\n", 2, "expected an array of 3 numbers");
  expect_error("WorldBegin\nColor 1 0\n", 2, "missing argument");
  expect_error("WorldBegin\nTranslate 1 2 3 4\n", 2, "too many arguments");
  expect_error("WorldBegin\nSides 3\n", 2, "Sides");
  expect_error("WorldBegin\nConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0]\n", 2, "16 numbers");
  expect_error("WorldBegin\nRotate 90 0 0 0\n", 2, "axis is zero");
  expect_error("WorldBegin\nOrientation \"sideways\"\n", 2, "orientation must be");
  expect_error("Projection \"perspective\" \"fov\" 180\n", 1, "fov");
  expect_error("Projection \"perspective\" \"fov\" \"wide\"\n", 1, "expects numbers");
  expect_error("Clipping 0 10\n", 1, "0 < near < far");
  expect_error("DepthOfField 0 0.05 3\n", 1, "fstop > 0");
  expect_error("MotionBegin [0 1]\nTranslate 1 0 0\nMotionEnd\n", 1, "2 times but 1 requests");
  expect_error("MotionBegin [0 1]\nTranslate 1 0 0\nScale 1 1 1\nMotionEnd\n", 3, "of one kind");
  expect_error("WorldBegin\nMotionBegin [0 1]\nPointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0]\n"
               "PointsPolygons [4] [0 1 2 3] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\nMotionEnd\n", 4, "topology");
  expect_error("Shutter 1 0\n", 1, "open <= close");
  expect_error("DepthOfField 2 0.05 -1\n", 1, "focaldistance > 0");
  expect_error("ScreenWindow 1 1 -1 1\n", 1, "empty screen window");
  expect_error("PixelSamples 1000 2\n", 1, "samples per axis");
  expect_error("PixelFilter \"box\" 0 1\n", 1, "filter widths");
  expect_error("ShadingRate -1\n", 1, "shading rate");
  expect_error("Declare \"x\" \"uniform banana\"\n", 1, "malformed declaration");
  // NaN and infinity have no RIB literal; written out they lex as names.
  expect_error("WorldBegin\nPolygon \"P\" [0 0 0  1 NaN 0  0 1 0]\n", 2, "'NaN' in an array is not a finite number");
  expect_error("WorldBegin\nPolygon \"P\" [0 0 0  1 inf 0  0 1 0]\n", 2, "'inf' in an array is not a finite number");
  expect_error("WorldBegin\nSurface \"plastic\" \"Ka\"\n", 2, "\"Ka\" has no value");
  expect_error("WorldBegin\nSurface \"plastic\" 1 2\n", 2, "expected a parameter name");
  expect_error("WorldBegin\nSurface \"plastic\" \"Ka\" [1 2]\n", 2, "\"Ka\" expects 1 number");
  expect_error("WorldBegin\nSurface \"plastic\" \"bogus float Ka\" 1\n", 2, "malformed inline declaration");
  expect_error("WorldBegin\nAttribute \"identifier\" \"name\" 3\n", 2, "expects one string");
}

TEST(RibErrors, GeometryCountsAndIndices) {
  expect_error("WorldBegin\nPolygon \"P\" [0 0 0 1 0]\n", 2, "multiple of 3");
  expect_error("WorldBegin\nPolygon \"P\" [\"a\" \"b\"]\n", 2, "expects numbers");
  expect_error("WorldBegin\nPolygon \"P\" [0 0 0 1 0 0]\n", 2, "at least 3 vertices");
  expect_error("WorldBegin\nPolygon \"N\" [0 0 1 0 0 1 0 0 1]\n", 2, "missing \"P\"");
  expect_error("WorldBegin\nPolygon \"Pw\" [0 0 0 1 1 0 0 0 0 1 0 1]\n", 2, "w = 0");
  expect_error("WorldBegin\nPolygon \"float P\" [0 0 0 1 0 0 0 1 0]\n", 2, "must hold points");
  expect_error("WorldBegin\nPointsPolygons [3] [0 1 2 3] " + std::string(kTri) + "\n", 2, "adds up to 3");
  expect_error("WorldBegin\nPointsPolygons [3]\n[0 1 5]\n" + std::string(kTri) + "\n", 3,
               "vertex index 5 (entry 2) is out of range: \"P\" has 3 points");
  expect_error("WorldBegin\nPointsPolygons [3] [0 -1 2] " + std::string(kTri) + "\n", 2, "vertices[1]");
  expect_error("WorldBegin\nPointsPolygons [3.5] [0 1 2] " + std::string(kTri) + "\n", 2, "nvertices[0]");
  expect_error("WorldBegin\nPointsPolygons [2] [0 1] " + std::string(kTri) + "\n", 2, "nvertices[0]");
  expect_error("WorldBegin\nPointsPolygons \"P\" [0 1] " + std::string(kTri) + "\n", 2,
               "expected an array of numbers");
  expect_error("WorldBegin\nGeneralPolygon [3 3] " + std::string(kTri) + "\n", 2, "loops need 6");
  expect_error("WorldBegin\nPointsGeneralPolygons [2] [3] [0 1 2] " + std::string(kTri) + "\n", 2,
               "nloops adds up to 2");
  const std::string quad = " \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n";
  expect_error("WorldBegin\nSubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"crease\"] [2 1] [0 9] [1]" + quad,
               2, "vertex 9 is out of range");
  expect_error("WorldBegin\nSubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"hole\"] [1 0] [1] []" + quad, 2,
               "face 1 is out of range");
  expect_error("WorldBegin\nSubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"crease\"] [2] [0 1] [1]" + quad,
               2, "nargs needs 2 entries per tag");
  expect_error("WorldBegin\nSubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"crease\"] [2 1] [0 1 2] [1]" + quad,
               2, "intargs has 3 entries, nargs asks for 2");
  expect_error("WorldBegin\nSubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"crease\"] [2 1] [0 1] [-1]" + quad,
               2, "negative sharpness");
  expect_error("WorldBegin\nSubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"interpolateboundary\"] [1 0] [7] []" +
                   quad,
               2, "mode must be 0, 1 or 2");
}

TEST(RibErrors, HugeCountsAllocateNothing) {
  // Counts far beyond the data are errors before any allocation.
  expect_error("WorldBegin\nPointsPolygons [2147483647] [0 1 2] " + std::string(kTri) + "\n", 2, "adds up to");
  expect_error("WorldBegin\nPointsPolygons [2147483648] [0 1 2] " + std::string(kTri) + "\n", 2, "nvertices[0]");
  expect_error("WorldBegin\nPointsPolygons [2147483647 2147483647 2147483647] [0 1 2] " + std::string(kTri) + "\n",
               2, "adds up to 6442450941");
  expect_error("WorldBegin\nSubdivisionMesh \"catmull-clark\" [3] [0 1 2] [\"crease\"] [2147483647 1] [0 1] [1] " +
                   std::string(kTri) + "\n",
               2, "nargs asks for 2147483647");
  expect_error("WorldBegin\nPatchMesh \"bicubic\" 2147483647 \"nonperiodic\" 2147483647 \"nonperiodic\" " +
                   std::string(kTri) + "\n",
               2, "nu * nv");
  expect_error("Format 2147483647 2147483647 1\n", 1, "expected an integer in [1, 65536]");
  expect_error("WorldBegin\nGeneralPolygon [2147483647] " + std::string(kTri) + "\n", 2, "loops need");
}

TEST(RibErrors, HandlesAndStructure) {
  expect_error("WorldBegin\nIlluminate 7 1\n", 2, "unknown light handle #7");
  expect_error("WorldBegin\nIlluminate \"key\" 1\n", 2, "unknown light handle \"key\"");
  expect_error("WorldBegin\n\nObjectInstance 3\n", 3, "unknown object handle #3");
  expect_error("Format 1 1 1\nWorldEnd\n", 2, "WorldEnd: without a matching WorldBegin");
  expect_error("WorldBegin\nAttributeBegin\nTransformEnd\n", 3, "innermost open block is AttributeBegin at bad.rib:2");
  expect_error("WorldBegin\nAttributeEnd\nWorldEnd\n", 2, "without a matching AttributeBegin");
  expect_error("WorldBegin\nWorldBegin\n", 2, "nested WorldBegin");
  expect_error("WorldBegin\nPolygon " + std::string(kTri) + "\n", 1, "WorldBegin is not closed");
  expect_error("WorldBegin\nAttributeBegin\nWorldEnd\n", 3, "innermost open block is AttributeBegin");
  expect_error("Format 1 1 1\nPolygon " + std::string(kTri) + "\n", 2, "outside WorldBegin/WorldEnd");
  expect_error("WorldBegin\nProjection \"perspective\"\n", 2, "inside the world block");
  expect_error("FrameBegin 1\nFrameBegin 2\n", 2, "FrameBegin inside FrameBegin");
  expect_error("ObjectBegin 1\nObjectBegin 2\n", 2, "nested ObjectBegin");
  expect_error("ObjectBegin 1\nWorldBegin\n", 2, "WorldBegin inside an object definition");
  expect_error("MotionBegin [0 1]\nMotionBegin [0 1]\n", 2, "nested motion blocks");
  expect_error("MotionEnd\n", 1, "without a matching MotionBegin");
  expect_error("WorldBegin\nCoordSysTransform \"nowhere\"\n", 2, "unknown coordinate system");
  expect_error("CoordSysTransform \"world\"\n", 1, "not defined before WorldBegin");
  expect_error("Scale 0 0 0\nWorldBegin\n", 2, "camera transformation is singular");
  expect_error("WorldBegin\nLightSource \"distantlight\" 1 \"from\" [1 1 1] \"to\" [1 1 1]\n", 2,
               "coincide");
  expect_error("WorldBegin\nLightSource \"pointlight\" 1 \"from\" [1 1]\n", 2, "multiple of 3");
}

// Each error names the line of the offending parameter, not the request's.
TEST(RibErrors, LightShadowParameters) {
  expect_error("WorldBegin\nLightSource \"pointlight\" 1\n  \"float micropoly:radius\" [-0.5]\n", 3,
               "\"micropoly:radius\" must be a finite number >= 0");
  expect_error("WorldBegin\nLightSource \"spotlight\" 1 \"intensity\" 2\n\n  \"micropoly:radius\" -1\n", 4,
               "micropoly:radius");
  expect_error("WorldBegin\nLightSource \"spotlight\" 1 \"float micropoly:radius\" [1 2]\n", 2,
               "\"micropoly:radius\" expects 1 number");
  expect_error("WorldBegin\nLightSource \"distantlight\" 1\n  \"float micropoly:angle\" [3.1416]\n", 3,
               "\"micropoly:angle\" must be an angle in [0, pi]");
  expect_error("WorldBegin\nLightSource \"distantlight\" 1 \"float micropoly:angle\" [-0.01]\n", 2,
               "micropoly:angle");
  expect_error("WorldBegin\nLightSource \"pointlight\" 1\n\"integer micropoly:softfalloff\" [2]\n", 3,
               "\"micropoly:softfalloff\" expects one integer in [0, 1]");
  expect_error("WorldBegin\nLightSource \"spotlight\" 1 \"micropoly:softfalloff\" [0.5]\n", 2,
               "micropoly:softfalloff");
  expect_error("WorldBegin\nLightSource \"pointlight\" 1\n  \"shadowname\" [1]\n", 3,
               "\"shadowname\" expects strings");
  expect_error("WorldBegin\nLightSource \"distantlight\" 1\n  \"float shadowname\" [1]\n", 3,
               "\"shadowname\" expects one string");
  expect_error("WorldBegin\nLightSource \"micropoly_arealight\" 1 \"shadowname\" [\"a\" \"b\"]\n", 2,
               "\"shadowname\" expects one string");
}

TEST(RibErrors, VisibilityValues) {
  expect_error("WorldBegin\nAttribute \"visibility\"\n  \"int camera\" [2]\n", 3,
               "\"camera\" expects one integer in [0, 1]");
  expect_error("WorldBegin\nAttribute \"visibility\" \"int camera\" [1]\n  \"int transmission\" [-1]\n", 3,
               "\"transmission\" expects one integer in [0, 1]");
  expect_error("WorldBegin\nAttribute \"visibility\" \"transmission\" [0.5]\n", 2, "transmission");
  expect_error("WorldBegin\nAttribute \"visibility\" \"string transmission\" [\"opaque\"]\n", 2, "transmission");
}

TEST(RibErrors, SamplerAndSampleMemory) {
  expect_error("Option \"micropoly\" \"string sampler\" \"fast\"\n", 1,
               "\"sampler\" must be \"auto\", \"tiles\", \"micropolygons\" or \"bins\"");
  expect_error("Option \"micropoly\" \"string visibilityfirst\" \"later\"\n", 1,
               "\"visibilityfirst\" must be \"auto\", \"on\" or \"off\"");
  expect_error("Option \"micropoly\"\n\"float samplememory\" [0]\n", 2, "\"samplememory\" must be");
  expect_error("Option \"micropoly\" \"float samplememory\" [-512]\n", 1, "samplememory");
}

TEST(RibErrors, ShadowOptionsAndProgramAlpha) {
  expect_error("Option \"micropoly\" \"integer shadows\" [2]\n", 1, "\"shadows\" expects one integer in [0, 1]");
  expect_error("Option \"micropoly\" \"integer shadows\" [1]\n  \"float shadowmemory\" [0]\n", 2,
               "\"shadowmemory\" must be a positive number of MiB");
  expect_error("Option \"micropoly\" \"float shadowmemory\" [-64]\n", 1, "shadowmemory");
  expect_error("Option \"micropoly\"\n\"float shadowshadingrate\" [0]\n", 2, "\"shadowshadingrate\" must be");
  expect_error("Option \"micropoly\" \"float shadowshadingrate\" [-1]\n", 1, "shadowshadingrate");
  expect_error("WorldBegin\nAttribute \"micropoly\" \"integer material\" [1] \"string program\" [\"x\"]\n"
               "  \"integer programalpha\" [3]\n",
               3, "\"programalpha\" expects one integer in [0, 2]");
}

TEST(RibErrors, PrincipledFlags) {
  expect_error("WorldBegin\nSurface \"micropoly_principled\" \"integer multiscatter\" [2]\n", 2,
               "\"multiscatter\" expects one integer in [0, 1]");
  expect_error("WorldBegin\nSurface \"micropoly_principled\"\n  \"integer retrodiffuse\" [-1]\n", 3,
               "\"retrodiffuse\" expects one integer in [0, 1]");
}

// Object Info's values and the holdout option: out of range, not numbers,
// not finite.
TEST(RibErrors, ObjectInfoAndHoldout) {
  expect_error("WorldBegin\nAttribute \"micropoly\" \"float objectrandom\" [1.5]\n", 2,
               "\"objectrandom\" must be a number in [0, 1]");
  expect_error("WorldBegin\nAttribute \"micropoly\" \"float objectindex\" [\"two\"]\n", 2, "objectindex");
  // Non-finite numbers never reach it: the lexer refuses them.
  expect_error("WorldBegin\nAttribute \"micropoly\" \"color objectcolor\" [1 1e999 0]\n", 2, "out of range");
  expect_error("Option \"micropoly\" \"integer holdoutcovers\" [3]\n", 1,
               "\"holdoutcovers\" expects one integer in [0, 1]");
}

TEST(RibErrors, Archives) {
  expect_error("WorldBegin\nReadArchive \"does_not_exist.rib\"\n", 2, "cannot read");
  expect_error("ReadArchive \"/dev/zero\"\n", 1, "ReadArchive \"/dev/zero\" refused: /dev/zero is outside the scene's folder");
  const std::string dir = testing::TempDir();
  {
    std::ofstream(dir + "/rib_self.rib") << "# includes itself\nReadArchive \"rib_self.rib\"\n";
    std::ofstream(dir + "/rib_bad_inner.rib") << "Color [1 0 0]\n\nTranslate 1 \"two\" 3\n";
  }
  try {
    mp::read_rib_file(dir + "/rib_self.rib");
    FAIL() << "recursive ReadArchive did not fail";
  } catch (const mp::RibError& e) {
    EXPECT_NE(std::string(e.what()).find(":2: ReadArchive: archives nested deeper than"), std::string::npos)
        << e.what();
  }
  // Errors inside an archive name the archive file and its line.
  try {
    mp::read_rib_string("WorldBegin\nReadArchive \"rib_bad_inner.rib\"\nWorldEnd\n", "main.rib", dir);
    FAIL() << "no error";
  } catch (const mp::RibError& e) {
    EXPECT_NE(std::string(e.what()).find("rib_bad_inner.rib:3: Translate:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(mp::read_rib_file(dir + "/no_such_file.rib"), mp::RibError);
}

// --- junk ------------------------------------------------------------------------------------

std::string read_scene(const std::string& name) {
  std::ifstream in(kScenes + "/" + name, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Parses `text`: success or RibError are fine, anything else fails the test.
void must_parse_or_throw_rib_error(const std::string& text, const char* kind, int iteration) {
  try {
    mp::read_rib_string(text, "junk.rib", kScenes);
  } catch (const mp::RibError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("junk.rib:", 0) == 0 || msg.find(".rib:") != std::string::npos, true) << msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << kind << " iteration " << iteration << ": " << e.what();
  } catch (...) {
    ADD_FAILURE() << kind << " iteration " << iteration << ": unknown exception";
  }
}

TEST(RibJunk, RandomBytes) {
  std::mt19937 rng(20240611u);
  for (int it = 0; it < 20000; ++it) {
    const size_t len = rng() % 400;
    std::string text(len, '\0');
    for (char& c : text) c = static_cast<char>(rng() & 0xFF);
    must_parse_or_throw_rib_error(text, "bytes", it);
  }
}

TEST(RibJunk, RandomRibLikeText) {
  // Bytes drawn from RIB's own alphabet reach further into the parser.
  const std::string alphabet = "  \n\t[]\"\"#.-+eE0123456789WorldBeginEndPolygonPSides\\";
  std::mt19937 rng(77u);
  for (int it = 0; it < 20000; ++it) {
    const size_t len = rng() % 300;
    std::string text;
    for (size_t i = 0; i < len; ++i) text += alphabet[rng() % alphabet.size()];
    must_parse_or_throw_rib_error(text, "alphabet", it);
  }
}

TEST(RibJunk, RandomRequestSoup) {
  // Random well-formed tokens: real request names with random arguments.
  const std::vector<std::string> names = {
      "WorldBegin", "WorldEnd", "FrameBegin", "FrameEnd", "AttributeBegin", "AttributeEnd",
      "TransformBegin", "TransformEnd", "Translate", "Rotate", "Scale", "ConcatTransform",
      "Transform", "Identity", "Color", "Opacity", "Surface", "LightSource", "Illuminate", "Sides",
      "Orientation", "ReverseOrientation", "Polygon", "GeneralPolygon", "PointsPolygons",
      "PointsGeneralPolygons", "SubdivisionMesh", "Patch", "PatchMesh", "Basis", "ObjectBegin",
      "ObjectEnd", "ObjectInstance", "Format", "Projection", "ScreenWindow", "Clipping",
      "PixelSamples", "PixelFilter", "ShadingRate", "Display", "Declare", "Option", "Attribute",
      "CoordinateSystem", "CoordSysTransform", "MotionBegin", "MotionEnd", "Sphere", "ReadArchive",
      "CropWindow", "SolidBegin", "SolidEnd", "Points", "Torus", "Paraboloid", "Hyperboloid", "Disk"};
  const std::vector<std::string> words = {
      "P", "Pw", "N", "Ka", "fov", "from", "to", "catmull-clark", "bicubic", "bilinear", "periodic",
      "nonperiodic", "crease", "corner", "hole", "interpolateboundary", "b-spline", "hermite",
      "plastic", "matte", "spotlight", "pointlight", "distantlight", "perspective", "inside", "rh",
      "uniform float", "vertex point P", "identifier", "name", "world", "camera", "all_requests.rib"};
  std::mt19937 rng(4242u);
  auto number = [&]() -> std::string {
    switch (rng() % 6) {
      case 0: return std::to_string(static_cast<int>(rng() % 8));
      case 1: return std::to_string(static_cast<int>(rng() % 40) - 10);
      case 2: return std::to_string((rng() % 2000) / 100.0 - 5.0);
      case 3: return "2147483647";
      case 4: return "1e30";
      default: return std::to_string(rng() % 20);
    }
  };
  for (int it = 0; it < 10000; ++it) {
    std::string text;
    const int nreq = static_cast<int>(rng() % 30);
    for (int r = 0; r < nreq; ++r) {
      text += names[rng() % names.size()];
      const int nargs = static_cast<int>(rng() % 7);
      for (int a = 0; a < nargs; ++a) {
        switch (rng() % 4) {
          case 0: text += " " + number(); break;
          case 1: text += " \"" + words[rng() % words.size()] + "\""; break;
          case 2: {
            text += " [";
            const int n = static_cast<int>(rng() % 20);
            for (int k = 0; k < n; ++k) text += " " + number();
            text += " ]";
            break;
          }
          default: {
            text += " [";
            const int n = static_cast<int>(rng() % 4);
            for (int k = 0; k < n; ++k) text += " \"" + words[rng() % words.size()] + "\"";
            text += " ]";
          }
        }
      }
      text += "\n";
    }
    must_parse_or_throw_rib_error(text, "soup", it);
  }
}

TEST(RibJunk, MutatedSceneFiles) {
  const std::vector<std::string> sources = {read_scene("all_requests.rib"), read_scene("subdiv_creases.rib")};
  ASSERT_FALSE(sources[0].empty());
  std::mt19937 rng(99u);
  for (int it = 0; it < 5000; ++it) {
    std::string text = sources[static_cast<size_t>(it) % sources.size()];
    const int edits = 1 + static_cast<int>(rng() % 8);
    for (int e = 0; e < edits && !text.empty(); ++e) {
      const size_t pos = rng() % text.size();
      switch (rng() % 5) {
        case 0: text[pos] = static_cast<char>(rng() & 0xFF); break;                 // flip a byte
        case 1: text.erase(pos, 1 + rng() % 16); break;                              // delete
        case 2: text.insert(pos, text.substr(rng() % text.size(), rng() % 64)); break;  // duplicate
        case 3: text.resize(pos); break;                                              // truncate
        default: text[pos] = "[]\"#0-9e."[rng() % 9]; break;                         // RIB syntax
      }
    }
    must_parse_or_throw_rib_error(text, "mutation", it);
  }
}

}  // namespace
