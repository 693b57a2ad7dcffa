// Every folder of ../shared/data (listed in its README.md) loads through Kartograf's readers.
// Each count and value below was measured with a second, independent reader, not with Kartograf:
//  - PCD geometry (WIDTH/HEIGHT, finite points, first/last finite point, normals, (0,0,0) points):
//    Open3D 0.16.1, o3d.io.read_point_cloud on /usr/bin/python3, numpy on its arrays;
//  - PCD colours and labels: PCL 1.13's pcl_convert_pcd_ascii_binary to ascii, the integers parsed
//    as text (Open3D drops labels, and SOURCE.txt notes it misreads one rgba file);
//  - images: Open3D's o3d.io.read_image (libpng/libjpeg) and, for the NYU PGM and PPM, the bytes
//    parsed by hand in Python; PNG sizes from each file's IHDR chunk, read here byte by byte.
// Folders already covered elsewhere: 7scenes_redkitchen (sequence_test), tum_fr1_xyz_lists_only
// (tum_test), open3d_testdata/RGBD/trajectory.log (sequence_test).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <ostream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/pcd.hpp"
#include "kartograf/formats/ply.hpp"
#include "kartograf/formats/sequence.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

namespace fs = std::filesystem;

fs::path data(const std::string& relative) {
  return testing::data_dir() / relative;
}

// Files under folder (recursively) whose name ends with suffix, relative to the data folder.
std::set<std::string> files_in(const std::string& folder, const std::string& suffix) {
  std::set<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(data(folder))) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.size() >= suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      names.insert(fs::relative(entry.path(), testing::data_dir()).generic_string());
    }
  }
  return names;
}

// ---------------------------------------------------------------------------------------------
// The README's folder list: a folder added there without a test here fails.

TEST(SharedData, EveryFolderInTheReadmeIsCovered) {
  std::ifstream readme(data("README.md"));
  ASSERT_TRUE(readme) << "no README.md in " << testing::data_dir();
  const std::regex row(R"(^\| `([A-Za-z0-9_]+)/` \|)");
  std::set<std::string> listed;
  for (std::string line; std::getline(readme, line);) {
    std::smatch match;
    if (std::regex_search(line, match, row)) listed.insert(match[1]);
  }
  const std::set<std::string> covered = {"7scenes_redkitchen",  // sequence_test
                                         "7scenes_redkitchen_300_599",
                                         "sun3d_studyroom_fragment1",  // sequence_input_test
                                         "tum_fr1_xyz_lists_only",     // tum_test
                                         "open3d_testdata",
                                         "pcl_clouds",
                                         "pcl_mosd",
                                         "pcl_tutorials",
                                         "dlut_laser_scans",
                                         "ipa_room_maps"};
  EXPECT_EQ(listed, covered);
  for (const std::string& folder : listed) EXPECT_TRUE(fs::is_directory(data(folder))) << folder;
}

// ---------------------------------------------------------------------------------------------
// PCD files

struct PcdFacts {
  const char* file;
  int width, height;
  std::size_t finite;  // points with three finite coordinates
  std::size_t zeros;   // finite points at (0, 0, 0): the DLUT scans' "no return"
  std::size_t first;   // index of the first and last finite point, and the points
  Eigen::Vector3f first_point;
  std::size_t last;
  Eigen::Vector3f last_point;
  std::optional<Eigen::Vector3f> first_normal;  // normal of the first point, when the file has them
  std::optional<Rgb8> first_color, last_color;
};

// Measured with Open3D and PCL as said at the top (numbers as Python printed them).
using V = Eigen::Vector3f;
const std::vector<PcdFacts> kPcdFacts = {
    {"dlut_laser_scans/A601.pcd", 361, 144, 51984, 1805, 0, V(0.1f, -6.934f, 0.825f), 51983,
     V(0.035f, 0.458f, 0.897f), std::nullopt, std::nullopt, std::nullopt},
    {"dlut_laser_scans/A603.pcd", 361, 148, 53428, 1525, 0, V(0.1f, -0.478f, 0.825f), 53427,
     V(0.035f, 0.381f, 0.897f), std::nullopt, std::nullopt, std::nullopt},
    {"dlut_laser_scans/A605.pcd", 361, 234, 84474, 2119, 0, V(0.037f, -0.405f, 0.603f), 84473,
     V(-0.001f, 0.836f, 0.637f), std::nullopt, std::nullopt, std::nullopt},
    {"dlut_laser_scans/B602.pcd", 361, 149, 53789, 1891, 0, V(0.1f, -0.852f, 0.825f), 53788,
     V(0.035f, 0.514f, 0.897f), std::nullopt, std::nullopt, std::nullopt},
    {"dlut_laser_scans/query_01.pcd", 361, 150, 54150, 1228, 0, V(0.1f, -0.483f, 0.825f), 54149,
     V(0.035f, 0.378f, 0.897f), std::nullopt, std::nullopt, std::nullopt},
    {"dlut_laser_scans/query_02.pcd", 361, 148, 53428, 1363, 0, V(0.1f, -0.491f, 0.825f), 53427,
     V(0.036f, 0.372f, 0.897f), std::nullopt, std::nullopt, std::nullopt},
    {"open3d_testdata/Feature/cloud_bin_0.pcd", 3903, 1, 3903, 0, 0,
     V(2.848907709121704f, 0.031390607357025146f, -1.7471659183502197f), 3902,
     V(2.832442283630371f, 0.3499086797237396f, -1.441496729850769f),
     V(-0.8276576995849609f, 0.3338222801685333f, -0.4511411190032959f), Rgb8{0, 0, 0},
     Rgb8{23, 18, 16}},
    {"open3d_testdata/Feature/cloud_bin_1.pcd", 3458, 1, 3458, 0, 0,
     V(2.8449065685272217f, 0.008786961436271667f, -1.81662917137146f), 3457,
     V(2.699355125427246f, 0.8624465465545654f, -1.790148377418518f),
     V(-0.8368020057678223f, 0.4994426965713501f, 0.224170982837677f), Rgb8{0, 0, 0},
     Rgb8{0, 0, 0}},
    {"open3d_testdata/fragment.pcd", 113662, 1, 113662, 0, 0,
     V(1.16796875f, 1.0180327892303467f, 0.96484375f), 113661,
     V(2.19140625f, 2.62890625f, 1.4578105211257935f),
     V(0.965461790561676f, -0.08612899482250214f, 0.24589692056179047f), Rgb8{127, 117, 106},
     Rgb8{116, 110, 102}},
    {"pcl_clouds/five_people.pcd", 640, 480, 239075, 0, 17301,
     V(-1.7318687438964844f, -1.2329047918319702f, 3.0460002422332764f), 305248,
     V(1.3913942575454712f, 1.1406056880950928f, 2.5320000648498535f), std::nullopt,
     Rgb8{138, 138, 126}, Rgb8{181, 167, 138}},
    {"pcl_clouds/grabber_sequences/pcd/frame_20121214T142255.814212.pcd", 640, 480, 271575, 0, 9616,
     V(-0.9102628231048584f, -0.673714280128479f, 1.5720000267028809f), 303958,
     V(0.37966856360435486f, 0.3195771276950836f, 0.7170000076293945f), std::nullopt,
     Rgb8{80, 82, 88}, Rgb8{19, 19, 19}},
    {"pcl_clouds/grabber_sequences/pcd/frame_20121214T142256.068683.pcd", 640, 480, 271395, 0, 9616,
     V(-0.9143162369728088f, -0.676714301109314f, 1.5790001153945923f), 303958,
     V(0.3791390657424927f, 0.31913143396377563f, 0.7160000205039978f), std::nullopt,
     Rgb8{84, 90, 95}, Rgb8{21, 21, 21}},
    {"pcl_clouds/grabber_sequences/pcd/frame_20121214T142256.332395.pcd", 640, 480, 271328, 0, 9615,
     V(-0.9086096286773682f, -0.6702857613563538f, 1.564000129699707f), 303958,
     V(0.37966856360435486f, 0.3195771276950836f, 0.7170000076293945f), std::nullopt,
     Rgb8{78, 85, 92}, Rgb8{14, 14, 14}},
    {"pcl_clouds/office1.pcd", 640, 480, 254456, 0, 8979,
     V(-2.2400128841400146f, -1.6818710565567017f, 3.9070000648498535f), 298927,
     V(-0.9900799989700317f, 0.8232532739639282f, 1.9040000438690186f), std::nullopt,
     Rgb8{166, 157, 147}, Rgb8{182, 180, 184}},
    {"pcl_clouds/organized_edge_1.pcd", 640, 480, 307200, 0, 0,
     V(-0.5611461400985718f, -0.42064008116722107f, 0.9353699088096619f), 307199,
     V(1.2317603826522827f, 0.9233383536338806f, 2.053211212158203f), std::nullopt,
     Rgb8{24, 100, 34}, Rgb8{24, 100, 34}},
    {"pcl_clouds/organized_edge_2.pcd", 640, 480, 307200, 0, 0,
     V(-0.5624029040336609f, -0.4215821623802185f, 0.9374648332595825f), 307199,
     V(1.2271925210952759f, 0.9199142456054688f, 2.0455970764160156f), std::nullopt,
     Rgb8{24, 100, 34}, Rgb8{24, 100, 34}},
    {"pcl_clouds/sac_plane_test.pcd", 3283, 1, 3283, 0, 0, V(1.068f, 0.094720997f, -0.016231f),
     3282, V(1.2798001f, -0.41073f, -0.18623f), V(-0.33680952f, -0.5904243f, -0.73345655f),
     std::nullopt, std::nullopt},
    {"pcl_clouds/table_scene_mug_stereo_textured.pcd", 640, 480, 209280, 0, 6538,
     V(-0.3819099962711334f, -0.448199987411499f, 2.0257999897003174f), 300789,
     V(0.22537000477313995f, 0.17903999984264374f, 0.7029200196266174f), std::nullopt,
     Rgb8{67, 67, 62}, Rgb8{233, 235, 19}},
    {"pcl_mosd/test0.pcd", 640, 480, 189198, 0, 63269,
     V(0.4957199990749359f, -0.30564001202583313f, 1.1339999437332153f), 306584,
     V(-0.3382771909236908f, 0.27417048811912537f, 0.6010000109672546f), std::nullopt,
     Rgb8{167, 150, 145}, Rgb8{177, 161, 169}},
    {"pcl_mosd/test16.pcd", 640, 480, 187775, 0, 44474,
     V(-0.006065715104341507f, -0.1880372017621994f, 0.5790001153945923f), 306584,
     V(-0.34221720695495605f, 0.2773638069629669f, 0.6079999804496765f), std::nullopt,
     Rgb8{141, 149, 153}, Rgb8{164, 153, 164}},
    {"pcl_mosd/test24.pcd", 640, 480, 185257, 0, 65621,
     V(0.06331238150596619f, -0.4049048125743866f, 1.5460000038146973f), 306585,
     V(-0.35227811336517334f, 0.2864876091480255f, 0.628000020980835f), std::nullopt,
     Rgb8{141, 122, 112}, Rgb8{170, 154, 157}},
    {"pcl_mosd/test31.pcd", 640, 480, 170909, 0, 71186,
     V(-0.5475990176200867f, -0.40557050704956055f, 1.656999945640564f), 306586,
     V(-0.3577904999256134f, 0.2919619083404541f, 0.6399999856948853f), std::nullopt,
     Rgb8{195, 181, 181}, Rgb8{196, 185, 188}},
    {"pcl_mosd/test43.pcd", 170986, 1, 170986, 0, 0,
     V(-0.5700829029083252f, -0.4036124050617218f, 1.6490000486373901f), 170985,
     V(-0.08789333701133728f, 0.07253333926200867f, 0.8960000276565552f), std::nullopt,
     Rgb8{195, 196, 200}, Rgb8{89, 79, 70}},
    {"pcl_mosd/test55.pcd", 640, 480, 175178, 0, 73312,
     V(0.07410000264644623f, -0.28613999485969543f, 1.1970000267028809f), 306585,
     V(-0.3556438088417053f, 0.2892248034477234f, 0.6340000033378601f), std::nullopt,
     Rgb8{88, 80, 119}, Rgb8{179, 160, 170}},
    {"pcl_mosd/test56.pcd", 165114, 1, 165114, 0, 0,
     V(0.07826189696788788f, -0.2249000072479248f, 0.8650001287460327f), 165113,
     V(-0.06535714119672775f, 0.07407142966985703f, 0.9150000214576721f), std::nullopt,
     Rgb8{113, 120, 119}, Rgb8{95, 99, 124}},
    {"pcl_mosd/test57.pcd", 640, 480, 171483, 0, 53492,
     V(0.08910000324249268f, -0.26560288667678833f, 0.890999972820282f), 306585,
     V(-0.3550828993320465f, 0.28876858949661255f, 0.6330000162124634f), std::nullopt,
     Rgb8{179, 130, 78}, Rgb8{199, 181, 188}},
    {"pcl_tutorials/pairwise/capture0001.pcd", 640, 480, 249647, 0, 17975,
     V(-1.4948029518127441f, -1.1952769756317139f, 2.9670000076293945f), 305253,
     V(0.845280110836029f, 0.681119978427887f, 1.5119999647140503f), std::nullopt, std::nullopt,
     std::nullopt},
    {"pcl_tutorials/pairwise/capture0002.pcd", 640, 480, 249931, 0, 17949,
     V(-1.0535470247268677f, -0.7670400142669678f, 1.9040000438690186f), 305254,
     V(0.895280122756958f, 0.7189599871635437f, 1.5959999561309814f), std::nullopt, std::nullopt,
     std::nullopt},
    {"pcl_tutorials/pairwise/capture0003.pcd", 640, 480, 248494, 0, 17964,
     V(-0.9571657776832581f, -0.7348114848136902f, 1.8240000009536743f), 305253,
     V(0.8564609885215759f, 0.6901295781135559f, 1.531999945640564f), std::nullopt, std::nullopt,
     std::nullopt},
    {"pcl_tutorials/pairwise/capture0004.pcd", 640, 480, 244573, 0, 17952,
     V(-1.8120720386505127f, -1.3330539464950562f, 3.309000015258789f), 305254,
     V(0.9294980764389038f, 0.7464390993118286f, 1.656999945640564f), std::nullopt, std::nullopt,
     std::nullopt},
    {"pcl_tutorials/pairwise/capture0005.pcd", 640, 480, 244977, 0, 17952,
     V(-1.8120720386505127f, -1.3330539464950562f, 3.309000015258789f), 305254,
     V(0.9165961742401123f, 0.7360780835151672f, 1.6339999437332153f), std::nullopt, std::nullopt,
     std::nullopt},
    {"pcl_tutorials/region_growing_rgb_tutorial.pcd", 640, 480, 259847, 0, 8972,
     V(-0.7227733731269836f, -0.5303468108177185f, 1.2319999933242798f), 298918,
     V(-0.4646286070346832f, 0.37400949001312256f, 0.8650001287460327f), std::nullopt,
     Rgb8{147, 128, 96}, Rgb8{179, 160, 149}},
    {"pcl_tutorials/region_growing_tutorial.pcd", 108104, 1, 108104, 0, 0,
     V(1269.0f, 4086.10009765625f, 14158.2197265625f), 108103,
     V(-2877.199951171875f, 11531.98046875f, 13890.990234375f), std::nullopt, Rgb8{90, 16, 141},
     Rgb8{4, 172, 187}},
    {"pcl_tutorials/room_scan1.pcd", 112586, 1, 112586, 0, 0,
     V(0.10718189924955368f, 0.0529458187520504f, 1.6857659816741943f), 112585,
     V(0.0016759870341047645f, 0.0008218492730520666f, -0.10998419672250748f), std::nullopt,
     std::nullopt, std::nullopt},
    {"pcl_tutorials/room_scan2.pcd", 112624, 1, 112624, 0, 0,
     V(0.10515809804201126f, 0.0583319291472435f, 1.6957420110702515f), 112623,
     V(0.0016253780340775847f, 0.000917886383831501f, -0.10998419672250748f), std::nullopt,
     std::nullopt, std::nullopt},
};

// So that a failing case names its file rather than dumping bytes.
void PrintTo(const PcdFacts& facts, std::ostream* out) {
  *out << facts.file;
}

class SharedPcd : public ::testing::TestWithParam<PcdFacts> {};

TEST(SharedData, EveryPcdFileOnDiskIsInTheTable) {
  std::set<std::string> on_disk;
  for (const char* folder :
       {"pcl_clouds", "pcl_mosd", "pcl_tutorials", "dlut_laser_scans", "open3d_testdata"}) {
    on_disk.merge(files_in(folder, ".pcd"));
  }
  std::set<std::string> tabled;
  for (const PcdFacts& facts : kPcdFacts) tabled.insert(facts.file);
  EXPECT_EQ(on_disk, tabled);
  EXPECT_EQ(tabled.size(), 35u);
}

TEST_P(SharedPcd, LoadsWithTheIndependentlyMeasuredCountsAndValues) {
  const PcdFacts& facts = GetParam();
  const io::PcdCloud cloud = io::read_pcd(data(facts.file));
  EXPECT_EQ(cloud.width, facts.width);
  EXPECT_EQ(cloud.height, facts.height);
  ASSERT_EQ(cloud.size(), std::size_t(facts.width) * std::size_t(facts.height));
  EXPECT_EQ(cloud.organized(), facts.height > 1);

  std::vector<std::size_t> finite;
  std::size_t zeros = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.points[i].allFinite()) {
      // Missing points are NaN in all three coordinates, as PCL writes them.
      EXPECT_TRUE(cloud.points[i].array().isNaN().all()) << i;
      continue;
    }
    finite.push_back(i);
    if (cloud.points[i].isZero()) ++zeros;
  }
  ASSERT_EQ(finite.size(), facts.finite);
  EXPECT_EQ(zeros, facts.zeros);
  EXPECT_EQ(finite.front(), facts.first);
  EXPECT_EQ(finite.back(), facts.last);
  EXPECT_EQ(cloud.points[facts.first], facts.first_point);
  EXPECT_EQ(cloud.points[facts.last], facts.last_point);
  EXPECT_EQ(cloud.normals.empty(), !facts.first_normal.has_value());
  if (facts.first_normal) {
    EXPECT_EQ(cloud.normals[facts.first], *facts.first_normal);
  }
  EXPECT_EQ(cloud.colors.empty(), !facts.first_color.has_value());
  if (facts.first_color) {
    EXPECT_EQ(cloud.colors[facts.first], *facts.first_color);
    EXPECT_EQ(cloud.colors[facts.last], *facts.last_color);
  }

  // The conversions keep exactly the finite points.
  const PointCloud valid = cloud.to_point_cloud();
  EXPECT_EQ(valid.size(), facts.finite);
  EXPECT_EQ(valid.points.back(), facts.last_point);
  if (cloud.organized()) {
    const PointImage image = cloud.to_point_image();
    EXPECT_EQ(static_cast<std::size_t>(std::count_if(image.pixels().begin(), image.pixels().end(),
                                                     [](const Point4f& p) { return is_valid(p); })),
              facts.finite);
    const std::size_t first = facts.first;
    EXPECT_EQ(image(int(first % std::size_t(facts.width)), int(first / std::size_t(facts.width))),
              Point4f(facts.first_point.x(), facts.first_point.y(), facts.first_point.z(), 1.0f));
  }
}

INSTANTIATE_TEST_SUITE_P(SharedData, SharedPcd, ::testing::ValuesIn(kPcdFacts),
                         [](const ::testing::TestParamInfo<PcdFacts>& info) {
                           std::string name = info.param.file;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

// The mOSD labels, counted per label with PCL (ascii conversion, then the label column).
TEST(SharedData, MosdLabelsCountPerLabelAndZeroMeansNoPoint) {
  const std::vector<std::pair<const char*, std::map<std::uint32_t, std::size_t>>> expected = {
      {"pcl_mosd/test0.pcd", {{0, 118002}, {1, 162732}, {20, 16630}, {30, 9836}}},
      {"pcl_mosd/test16.pcd", {{0, 119425}, {1, 152513}, {20, 17450}, {30, 5617}, {40, 12195}}},
      {"pcl_mosd/test24.pcd", {{0, 121943}, {1, 160104}, {20, 12770}, {30, 9003}, {31, 3380}}},
      {"pcl_mosd/test31.pcd", {{0, 136291}, {1, 138329}, {20, 12425}, {30, 9906}, {40, 10249}}},
      {"pcl_mosd/test43.pcd",
       {{1, 123873},
        {20, 10207},
        {30, 5144},
        {40, 4364},
        {50, 12366},
        {60, 2278},
        {70, 7703},
        {80, 1549},
        {81, 3502}}},
      {"pcl_mosd/test55.pcd",
       {{0, 132022}, {1, 20714},  {2, 40786},  {3, 213},    {4, 3011},   {5, 2057},
        {6, 2723},   {7, 1271},   {20, 13184}, {30, 8180},  {40, 7025},  {50, 12475},
        {60, 4885},  {70, 6439},  {80, 3675},  {90, 14708}, {100, 5148}, {110, 7278},
        {120, 4747}, {130, 8019}, {140, 3634}, {150, 1909}, {151, 3097}}},
      {"pcl_mosd/test56.pcd",
       {{1, 76432},
        {2, 252},
        {3, 1343},
        {20, 5862},
        {30, 8629},
        {40, 6935},
        {50, 7784},
        {60, 4911},
        {70, 4886},
        {80, 3966},
        {90, 6137},
        {100, 4103},
        {110, 4936},
        {120, 10643},
        {130, 5958},
        {140, 4481},
        {150, 7856}}},
      {"pcl_mosd/test57.pcd",
       {{0, 135717}, {1, 51720},  {2, 1618},   {3, 4789},   {4, 4334},   {5, 5792},   {20, 5245},
        {30, 5849},  {40, 22135}, {50, 6797},  {60, 5334},  {61, 366},   {70, 6588},  {80, 14674},
        {90, 3633},  {91, 207},   {100, 2221}, {101, 2975}, {110, 2007}, {120, 2275}, {121, 2105},
        {130, 4535}, {140, 6217}, {150, 1304}, {151, 514},  {160, 2553}, {170, 5696}}},
  };
  for (const auto& [file, counts] : expected) {
    SCOPED_TRACE(file);
    const io::PcdCloud cloud = io::read_pcd(data(file));
    ASSERT_EQ(cloud.labels.size(), cloud.size());
    std::map<std::uint32_t, std::size_t> measured;
    for (std::uint32_t label : cloud.labels) ++measured[label];
    EXPECT_EQ(measured, counts);
    // Label 0 marks exactly the missing points (the unorganized frames have none).
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if ((cloud.labels[i] == 0) != !cloud.points[i].allFinite()) {
        ADD_FAILURE() << "point " << i << " has label " << cloud.labels[i];
        break;
      }
    }
    // README.mOSD: 1..9 the table plane, 10 x object id + part for objects.
    for (const auto& [label, count] : measured) {
      EXPECT_TRUE(label < 10 || label >= 20) << label;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// open3d_testdata: the PLY fragment, the ICP log, and the RGB-D images sequence_test leaves out

TEST(SharedData, Open3dColoredIcpFragmentPly) {
  // Open3D: 64365 points with normals and colours; the 127229 faces after them are skipped.
  const PointCloud cloud = io::read_ply(data("open3d_testdata/ColoredICP/frag_115.ply"));
  ASSERT_EQ(cloud.size(), 64365u);
  ASSERT_TRUE(cloud.has_normals());
  ASSERT_TRUE(cloud.has_colors());
  EXPECT_EQ(cloud.points.front(), Eigen::Vector3f(0.84765625f, 2.679497718811035f, 1.59765625f));
  EXPECT_EQ(cloud.points.back(), Eigen::Vector3f(2.571622610092163f, 1.58203125f, 0.60546875f));
  EXPECT_EQ(cloud.normals.front(),
            Eigen::Vector3f(-0.4354782998561859f, 0.4669536054134369f, -0.7696187496185303f));
  EXPECT_EQ(cloud.colors.front(), (Rgb8{120, 115, 114}));
}

TEST(SharedData, Open3dIcpInitLogIsARedwoodLog) {
  // The file, read as text: 2 entries "i j 57" + 4x4 rows.
  const Trajectory log = io::read_redwood_log(data("open3d_testdata/ICP/init.log"));
  ASSERT_EQ(log.size(), 2u);
  EXPECT_NEAR(log[0].pose.translation().x(), 0.32977900, 1e-12);
  EXPECT_NEAR(log[0].pose.translation().z(), 1.62919450, 1e-12);
  EXPECT_NEAR(log[1].pose.translation().y(), -0.02455154, 1e-12);
}

struct DepthFacts {
  const char* file;
  std::size_t nonzero;
  std::uint16_t median, centre;  // median of the nonzero values; the value at (320, 240)
};

std::uint16_t median_nonzero(const DepthImage& depth, std::size_t* nonzero) {
  std::vector<std::uint16_t> values;
  for (std::uint16_t d : depth.pixels()) {
    if (d != 0) values.push_back(d);
  }
  *nonzero = values.size();
  if (values.empty()) return 0;
  auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

TEST(SharedData, Open3dDepthImages) {
  // Open3D read_image + numpy (np.median of the nonzero values; an odd count for each file).
  const std::vector<DepthFacts> facts = {
      {"open3d_testdata/RGBD/depth/00000.png", 267129, 1861, 2195},
      {"open3d_testdata/RGBD/depth/00001.png", 267728, 1861, 2195},
      {"open3d_testdata/RGBD/depth/00002.png", 268183, 1861, 2195},
      {"open3d_testdata/RGBD/depth/00003.png", 268620, 1861, 2195},
      {"open3d_testdata/RGBD/depth/00004.png", 269051, 1861, 2195},
      {"open3d_testdata/depth.png", 256497, 1586, 766},
      {"open3d_testdata/depth_syn.png", 78673, 1451, 1247},
      {"open3d_testdata/RGBD/other_formats/TUM_depth.png", 248250, 12075, 10920},  // 1/5000 m
      {"open3d_testdata/RGBD/other_formats/SUN_depth.png", 251188, 21272, 0},      // bit-rotated
  };
  for (const DepthFacts& f : facts) {
    SCOPED_TRACE(f.file);
    const DepthImage depth = io::read_depth_png(data(f.file));
    ASSERT_EQ(depth.width(), 640);
    ASSERT_EQ(depth.height(), 480);
    std::size_t nonzero = 0;
    EXPECT_EQ(median_nonzero(depth, &nonzero), f.median);
    EXPECT_EQ(nonzero, f.nonzero);
    EXPECT_EQ(depth(320, 240), f.centre);
  }
  // SUN RGB-D stores depth rotated by 3 bits: the median raw value is 2659 mm (SOURCE.txt).
  const std::uint16_t raw = 21272;
  EXPECT_EQ(static_cast<std::uint16_t>((raw >> 3) | (raw << 13)), 2659);
}

TEST(SharedData, NyuDepthPgmIsLittleEndianDisparity) {
  // A 16-bit PGM is big-endian by the standard, and the reader decodes it so; NYU wrote it
  // little-endian, so the raw Kinect disparities (839..2047, 2047 = invalid, counted in Python
  // from the file's bytes) appear byte-swapped.
  const DepthImage depth =
      io::read_depth_png(data("open3d_testdata/RGBD/other_formats/NYU_depth.pgm"));
  ASSERT_EQ(depth.width(), 640);
  ASSERT_EQ(depth.height(), 480);
  auto swapped = [](std::uint16_t v) { return static_cast<std::uint16_t>((v >> 8) | (v << 8)); };
  std::uint16_t low = 65535, high = 0;
  std::size_t invalid = 0;
  for (std::uint16_t v : depth.pixels()) {
    low = std::min(low, swapped(v));
    high = std::max(high, swapped(v));
    if (swapped(v) == 2047) ++invalid;
  }
  EXPECT_EQ(low, 839);
  EXPECT_EQ(high, 2047);
  EXPECT_EQ(invalid, 22199u);
  EXPECT_EQ(swapped(depth(320, 240)), 977);
}

TEST(SharedData, Open3dColorImages) {
  // Open3D read_image + numpy per-channel means; JPEG decoders may differ by rounding.
  struct ColorFacts {
    const char* file;
    std::array<double, 3> mean;
    double tolerance;
  };
  const std::vector<ColorFacts> facts = {
      {"open3d_testdata/RGBD/color/00000.jpg", {207.90, 193.38, 184.38}, 0.5},
      {"open3d_testdata/RGBD/color/00004.jpg", {205.95, 190.93, 181.88}, 0.5},
      {"open3d_testdata/RGBD/other_formats/TUM_color.png", {118.06, 109.62, 102.91}, 0.01},
      {"open3d_testdata/RGBD/other_formats/SUN_color.jpg", {82.27, 75.58, 72.62}, 0.5},
  };
  for (const ColorFacts& f : facts) {
    SCOPED_TRACE(f.file);
    const RgbImage color = io::read_color_image(data(f.file));
    ASSERT_EQ(color.width(), 640);
    ASSERT_EQ(color.height(), 480);
    std::array<double, 3> sum{};
    for (const Rgb8& p : color.pixels()) {
      for (int c = 0; c < 3; ++c) sum[c] += p[c];
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c] / double(color.size()), f.mean[c], f.tolerance);
  }
  for (int i = 1; i <= 3; ++i) {
    const RgbImage frame =
        io::read_color_image(data("open3d_testdata/RGBD/color/0000" + std::to_string(i) + ".jpg"));
    EXPECT_EQ(frame.width(), 640);
  }
  // The PPM's first pixel, from the bytes after its "P6 640 480 255\n" header.
  const RgbImage nyu =
      io::read_color_image(data("open3d_testdata/RGBD/other_formats/NYU_color.ppm"));
  ASSERT_EQ(nyu.width(), 640);
  ASSERT_EQ(nyu.height(), 480);
  EXPECT_EQ(nyu(0, 0), (Rgb8{0xdc, 0xf8, 0xeb}));
}

// ---------------------------------------------------------------------------------------------
// ipa_room_maps: every PNG decodes as an 8-bit image of the size its IHDR chunk gives. (What the
// pixels mean is the occupancy-map reader's business and tested with it.)

struct PngHeader {
  int width = 0, height = 0, bit_depth = 0, color_type = -1;
};

PngHeader png_header(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary);
  std::array<unsigned char, 26> bytes{};
  stream.read(reinterpret_cast<char*>(bytes.data()), bytes.size());
  const std::array<unsigned char, 8> signature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!stream || !std::equal(signature.begin(), signature.end(), bytes.begin()) ||
      std::string(bytes.begin() + 12, bytes.begin() + 16) != "IHDR") {
    return {};
  }
  auto be32 = [&](int at) {
    return int(bytes[at]) << 24 | int(bytes[at + 1]) << 16 | int(bytes[at + 2]) << 8 |
           int(bytes[at + 3]);
  };
  return {be32(16), be32(20), bytes[24], bytes[25]};
}

// The colour types (0 grey, 2 RGB, 4 grey+alpha, 6 RGBA) of the PNGs in folder, each checked to
// be 8-bit and to decode to its IHDR size.
std::map<int, int> decode_pngs(const std::string& folder) {
  std::map<int, int> color_types;
  for (const std::string& file : files_in(folder, ".png")) {
    SCOPED_TRACE(file);
    const PngHeader header = png_header(data(file));
    EXPECT_EQ(header.bit_depth, 8);
    ++color_types[header.color_type];
    const OccupancyGrid map = io::read_png_map(data(file));
    EXPECT_EQ(map.width(), header.width);
    EXPECT_EQ(map.height(), header.height);
  }
  return color_types;
}

// Counts with find and `file` (8-bit grayscale / gray+alpha / RGB / RGBA): 96 PNGs, 50 of them
// test maps (10 maps x 4 variants + ground truth).
TEST(SharedData, IpaRoomTestMapPngsDecodeAs8BitImages) {
  EXPECT_EQ(files_in("ipa_room_maps", ".png").size(), 96u);
  EXPECT_EQ(files_in("ipa_room_maps/test_maps", "_gt_segmentation.png").size(), 10u);
  EXPECT_EQ(decode_pngs("ipa_room_maps/test_maps"),
            (std::map<int, int>{{0, 6}, {2, 21}, {4, 3}, {6, 20}}));
}

TEST(SharedData, IpaRoomTrainingMapPngsDecodeAs8BitImages) {
  EXPECT_EQ(decode_pngs("ipa_room_maps/training_maps"),
            (std::map<int, int>{{0, 40}, {2, 1}, {4, 3}, {6, 2}}));
}

}  // namespace
}  // namespace kartograf
