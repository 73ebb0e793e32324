// SPDX-License-Identifier: MIT
// Cameras and calibration files: checks, scaling to other frame sizes, ROS
// camera_info and OpenCV FileStorage YAML and XML as their tools write them,
// malformed files, files that cannot be read, the files shipped for the
// sample video.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include <gtest/gtest.h>

#include "blocking_read.h"
#include "frappe/camera.h"
#include <vector>

using namespace frappe;

namespace {

Camera camera640()
{
	Camera c = Camera::pinhole(700.0, 710.0, 319.5, 239.5, 640, 480);
	c.distortion = { -0.2, 0.05, 0.001, -0.002, 0.01 };
	return c;
}

} // namespace

TEST(Camera, Pinhole)
{
	const Camera c = Camera::pinhole(600.0, 610.0, 320.0, 240.0);
	const std::array<double, 9> m = { 600, 0, 320, 0, 610, 240, 0, 0, 1 };
	EXPECT_EQ(c.matrix, m);
	EXPECT_TRUE(c.distortion.empty());
	EXPECT_EQ(c.width, 0);
	EXPECT_EQ(c.height, 0);
	EXPECT_TRUE(c.valid());
}

TEST(Camera, ValidateSaysWhatIsWrong)
{
	const auto message = [](const Camera &c) {
		try {
			c.validate();
		} catch (const std::invalid_argument &e) {
			return std::string(e.what());
		}
		return std::string("(valid)");
	};
	Camera c = camera640();
	EXPECT_EQ(message(c), "(valid)");
	c.matrix[4] = -1.0;
	EXPECT_NE(message(c).find("fy must be positive"), std::string::npos) << message(c);
	c = camera640();
	c.matrix[2] = std::nan("");
	EXPECT_NE(message(c).find("entry 2 is not finite"), std::string::npos) << message(c);
	c = camera640();
	c.matrix[7] = 0.5;
	EXPECT_NE(message(c).find("last row"), std::string::npos) << message(c);
	c = camera640();
	c.distortion.resize(6);
	EXPECT_NE(message(c).find("6 coefficients"), std::string::npos) << message(c);
	c = camera640();
	c.distortion.resize(4);
	EXPECT_EQ(message(c), "(valid)");
	c.distortion.resize(8);
	EXPECT_EQ(message(c), "(valid)");
	c.distortion[7] = std::numeric_limits<double>::infinity();
	EXPECT_NE(message(c).find("coefficient 7 is not finite"), std::string::npos) << message(c);
	c = camera640();
	c.width = -640;
	EXPECT_NE(message(c).find("negative size"), std::string::npos) << message(c);
	c = camera640();
	c.height = 0;
	EXPECT_NE(message(c).find("both"), std::string::npos) << message(c);
}

/* A 640x480 calibration at 320x240 and 1280x960: the focal lengths scale,
 * the principal point keeps its place relative to the image's edges. */
TEST(Camera, ScaledToOtherSizes)
{
	const Camera c = camera640();
	EXPECT_TRUE(c.fits(640, 480));
	EXPECT_TRUE(c.fits(320, 240));
	EXPECT_TRUE(c.fits(1280, 960));
	EXPECT_TRUE(c.fits(854, 640)); /* 853.33 rounded */
	EXPECT_FALSE(c.fits(640, 360)); /* 16:9 from 4:3 */
	EXPECT_FALSE(c.fits(480, 480));
	EXPECT_FALSE(c.fits(0, 480));
	EXPECT_TRUE(Camera::pinhole(600, 600, 320, 240).fits(1920, 1080)); /* size unknown */

	const Camera half = c.scaledTo(320, 240);
	EXPECT_EQ(half.width, 320);
	EXPECT_EQ(half.height, 240);
	EXPECT_DOUBLE_EQ(half.matrix[0], 350.0);
	EXPECT_DOUBLE_EQ(half.matrix[4], 355.0);
	EXPECT_DOUBLE_EQ(half.matrix[2], 159.5); /* (319.5 + 0.5) / 2 - 0.5 */
	EXPECT_DOUBLE_EQ(half.matrix[5], 119.5);
	EXPECT_EQ(half.distortion, c.distortion);
	EXPECT_EQ(half.matrix[8], 1.0);

	const Camera twice = c.scaledTo(1280, 960);
	EXPECT_DOUBLE_EQ(twice.matrix[0], 1400.0);
	EXPECT_DOUBLE_EQ(twice.matrix[4], 1420.0);
	EXPECT_DOUBLE_EQ(twice.matrix[2], 639.5);
	EXPECT_DOUBLE_EQ(twice.matrix[5], 479.5);
	EXPECT_TRUE(twice.valid());

	const Camera same = c.scaledTo(640, 480);
	EXPECT_EQ(same.matrix, c.matrix);
	const Camera unknown = Camera::pinhole(600, 600, 320, 240);
	EXPECT_EQ(unknown.scaledTo(1920, 1080).matrix, unknown.matrix);
	EXPECT_THROW(c.scaledTo(0, 240), std::invalid_argument);

	/* Issue 34: a valid calibration of a 1x1 frame with a focal length
	 * near the largest double scaled to an infinite one, and no pose
	 * came, silently. Now the scaling says why. */
	Camera huge = Camera::pinhole(1e308, 1e308, 0.0, 0.0);
	huge.width = huge.height = 1;
	ASSERT_TRUE(huge.valid());
	try {
		huge.scaledTo(640, 480);
		ADD_FAILURE() << "scaled to an infinite focal length";
	} catch (const std::invalid_argument &e) {
		EXPECT_EQ(std::string(e.what()), "camera: scaled from 1x1 to 640x480 its matrix is no camera (fx inf, fy inf)");
	}
}

namespace {

/* As ROS's camera_calibration writes ost.yaml. */
const char kRos[] = R"(image_width: 640
image_height: 480
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [ 701.12345,    0.     ,  319.87654,
            0.     ,  702.5432 ,  240.1234 ,
            0.     ,    0.     ,    1.     ]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.281234, 0.074321, 0.000412, -0.000287, 0.000000]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1., 0., 0.,
         0., 1., 0.,
         0., 0., 1.]
projection_matrix:
  rows: 3
  cols: 4
  data: [ 600.3,    0.     ,  320.1, 0.     ,
            0.     ,  650.2 ,  240.5, 0.     ,
            0.     ,    0.     ,    1.     , 0.     ]
)";

/* As `rostopic echo` prints a sensor_msgs/CameraInfo message. */
const char kRosMessage[] = R"(header: 
  seq: 12
  stamp: 
    secs: 0
    nsecs:         0
  frame_id: "camera"
height: 480
width: 640
distortion_model: "rational_polynomial"
D: [0.35, -0.12, 0.0009, 0.0005, 0.02, 0.62, -0.06, 0.03]
K: [690.0, 0.0, 322.0, 0.0, 705.0, 236.0, 0.0, 0.0, 1.0]
R: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
P: [690.0, 0.0, 322.0, 0.0, 0.0, 705.0, 236.0, 0.0, 0.0, 0.0, 1.0, 0.0]
binning_x: 0
binning_y: 0
roi: 
  x_offset: 0
  y_offset: 0
  height: 0
  width: 0
  do_rectify: False
---
)";

/* As cv::FileStorage writes YAML (OpenCV's calibration sample's keys). */
const char kOpenCvYaml[] = R"(%YAML:1.0
---
calibration_time: "Tue 12 Mar 2024 10:00:00 CET"
nr_of_frames: 25
image_width: 1280
image_height: 720
board_width: 9
board_height: 6
square_size: 2.5000000000000000e+01
flags: 0
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 9.1234567890123457e+02, 0., 6.4012345678901234e+02, 0.,
       9.1334567890123457e+02, 3.6012345678901234e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ 1.2345678901234567e-01, -2.3456789012345678e-01,
       1.0000000000000000e-03, -2.0000000000000000e-03,
       9.8765432109876543e-02 ]
avg_reprojection_error: 2.1234567890123456e-01
per_view_reprojection_errors: !!opencv-matrix
   rows: 2
   cols: 1
   dt: f
   data: [ 2.01234567e-01, 2.21234567e-01 ]
)";

/* As cv::FileStorage writes XML. */
const char kOpenCvXml[] = R"(<?xml version="1.0"?>
<opencv_storage>
<calibration_time>"Tue 12 Mar 2024 10:00:00 CET"</calibration_time>
<!-- a comment -->
<image_width>1280</image_width>
<image_height>720</image_height>
<camera_matrix type_id="opencv-matrix">
  <rows>3</rows>
  <cols>3</cols>
  <dt>d</dt>
  <data>
    9.1234567890123457e+02 0. 6.4012345678901234e+02 0.
    9.1334567890123457e+02 3.6012345678901234e+02 0. 0. 1.</data></camera_matrix>
<distortion_coefficients type_id="opencv-matrix">
  <rows>1</rows>
  <cols>8</cols>
  <dt>d</dt>
  <data>
    1.2e-01 -2.3e-01 1.e-03 -2.e-03 9.8e-02 1.5e-01 -1.e-02 3.e-03</data></distortion_coefficients>
<avg_reprojection_error>2.1234567890123456e-01</avg_reprojection_error>
</opencv_storage>
)";

void expectMatrix(const Camera &c, std::array<double, 9> m)
{
	for (int i = 0; i < 9; ++i)
		EXPECT_EQ(c.matrix[i], m[i]) << "entry " << i;
}

std::string errorOf(std::string_view text, std::string_view origin = "cam.yaml")
{
	try {
		parseCalibration(text, origin);
	} catch (const std::invalid_argument &e) {
		return e.what();
	}
	return "(no error)";
}

std::string replaced(std::string s, std::string_view from, std::string_view to)
{
	const std::size_t at = s.find(from);
	EXPECT_NE(at, std::string::npos) << from;
	if (at != std::string::npos)
		s.replace(at, from.size(), to);
	return s;
}

/* A scratch directory of this test process, removed at exit. */
struct Scratch {
	std::filesystem::path dir = std::filesystem::temp_directory_path() /
				    ("frappe-test-calibration-" + std::to_string(::getpid()));
	Scratch() { std::filesystem::create_directories(dir); }
	~Scratch() { std::filesystem::remove_all(dir); }
	std::string write(const std::string &name, const std::string &text) const
	{
		const auto p = dir / name;
		std::ofstream(p, std::ios::binary) << text;
		return p.string();
	}
};

} // namespace

TEST(Calibration, RosCameraInfo)
{
	const Camera c = parseCalibration(kRos, "ost.yaml");
	EXPECT_EQ(c.width, 640);
	EXPECT_EQ(c.height, 480);
	expectMatrix(c, { 701.12345, 0, 319.87654, 0, 702.5432, 240.1234, 0, 0, 1 });
	EXPECT_EQ(c.distortion, (std::vector<double>{ -0.281234, 0.074321, 0.000412, -0.000287, 0.0 }));
}

TEST(Calibration, RosCameraInfoMessage)
{
	const Camera c = parseCalibration(kRosMessage, "info.yaml");
	EXPECT_EQ(c.width, 640);
	EXPECT_EQ(c.height, 480);
	expectMatrix(c, { 690, 0, 322, 0, 705, 236, 0, 0, 1 });
	EXPECT_EQ(c.distortion, (std::vector<double>{ 0.35, -0.12, 0.0009, 0.0005, 0.02, 0.62, -0.06, 0.03 }));
}

/* The size and matrix of both OpenCV samples. */
void expectOpenCvSample(const Camera &c)
{
	EXPECT_EQ(c.width, 1280);
	EXPECT_EQ(c.height, 720);
	expectMatrix(c, { 9.1234567890123457e+02, 0, 6.4012345678901234e+02, 0, 9.1334567890123457e+02,
			  3.6012345678901234e+02, 0, 0, 1 });
}

TEST(Calibration, OpenCvYaml)
{
	const Camera c = parseCalibration(kOpenCvYaml, "out_camera_data.yml");
	expectOpenCvSample(c);
	EXPECT_EQ(c.distortion, (std::vector<double>{ 1.2345678901234567e-01, -2.3456789012345678e-01, 1e-3,
						      -2e-3, 9.8765432109876543e-02 }));
}

TEST(Calibration, OpenCvXml)
{
	const Camera c = parseCalibration(kOpenCvXml, "out_camera_data.xml");
	expectOpenCvSample(c);
	EXPECT_EQ(c.distortion, (std::vector<double>{ 0.12, -0.23, 1e-3, -2e-3, 9.8e-2, 0.15, -0.01, 3e-3 }));
}

/* The other spellings: cameraMatrix / distCoeffs / imageSize, XML items,
 * block sequences, four coefficients, comments and quoted keys. */
TEST(Calibration, OtherSpellings)
{
	const Camera x = parseCalibration(R"(<?xml version="1.0"?>
<opencv_storage>
<imageSize>640 480</imageSize>
<cameraMatrix type_id="opencv-matrix"><rows>3</rows><cols>3</cols><dt>d</dt>
<data>600 0 &#51;20 0 610 240 0 0 1</data></cameraMatrix>
<distCoeffs><_>0.1</_><_>-0.05</_><_>0.001</_><_>0.002</_></distCoeffs>
</opencv_storage>)");
	EXPECT_EQ(x.width, 640);
	EXPECT_EQ(x.height, 480);
	expectMatrix(x, { 600, 0, 320, 0, 610, 240, 0, 0, 1 });
	EXPECT_EQ(x.distortion, (std::vector<double>{ 0.1, -0.05, 0.001, 0.002 }));

	const Camera y = parseCalibration(R"(# a hand-written file
image_size: [320,   # width
             240]   # height
"cameraMatrix":   # block sequence, one number a line
  - 300
  - 0.0
  - 160
  - 0
  - 305.5
  - 120
  - 0
  - 0
  - 1
dist_coeffs:
- 0.1
- -0.05
- 1e-3
- +0.002
- .01
- 0.2
- -0.03
- 0.004
- 0
- 0.
- -0
- 0e0
- .0
- 0.0
)");
	EXPECT_EQ(y.width, 320);
	EXPECT_EQ(y.height, 240);
	expectMatrix(y, { 300, 0, 160, 0, 305.5, 120, 0, 0, 1 });
	/* 14, the thin prism and tilt terms zero */
	EXPECT_EQ(y.distortion, (std::vector<double>{ 0.1, -0.05, 0.001, 0.002, 0.01, 0.2, -0.03, 0.004 }));

	const Camera z = parseCalibration("K: {rows: 3, cols: 3, data: [500, 0, 10, 0, 500, 20, 0, 0, 1]}\n"
					  "D: []\n");
	EXPECT_EQ(z.width, 0);
	expectMatrix(z, { 500, 0, 10, 0, 500, 20, 0, 0, 1 });
	EXPECT_TRUE(z.distortion.empty());
}

/* Each malformed file names the file and what is wrong, usually the key. */
TEST(Calibration, MalformedFilesSayWhatIsWrong)
{
	const std::string ros = kRos;
	const std::string xml = kOpenCvXml;
	const struct {
		std::string text;
		const char *mention;
	} cases[] = {
		{ replaced(ros, "0.     ,    0.     ,    1.     ]", "0.     ,    0.     ]"),
		  "camera_matrix: 8 numbers for 3 rows and 3 cols" },
		{ "camera_matrix: [1, 0, 0, 0, 1, 0, 0, 1]\ndistortion_coefficients: []\n",
		  "camera_matrix: 8 numbers, expected 9" },
		{ replaced(ros, "319.87654", "319.8x"), "camera_matrix: \"319.8x\" is not a number" },
		{ replaced(ros, "camera_matrix:", "camera_matrx:"), "no camera matrix" },
		{ replaced(ros, "distortion_coefficients:", "distortion:"), "no distortion coefficients" },
		{ replaced(ros, "plumb_bob", "equidistant"), "distortion_model: equidistant (fisheye) is not supported" },
		{ replaced(ros, "plumb_bob", "pinhole"), "distortion_model: \"pinhole\" is unknown" },
		{ replaced(replaced(ros, "cols: 5", "cols: 6"), "0.000000]", "0.0, 0.1]"),
		  "distortion_coefficients: 6 coefficients, expected 4, 5 or 8" },
		{ replaced(replaced(ros, "cols: 5", "cols: 8"), "0.000000]", "0.0, 0.1, 0.2, 0.3]"),
		  "distortion_coefficients: 8 coefficients, but plumb_bob has 5" },
		{ replaced(ros, "rows: 1\n  cols: 5", "rows: 5\n  cols: 5"), "distortion_coefficients: 5 numbers for 5 rows" },
		{ replaced(ros, "image_height: 480\n", ""), "image_width: given without image_height" },
		{ replaced(ros, "image_width: 640", "image_width: -640"), "image_width: must be positive" },
		{ replaced(ros, "image_width: 640", "image_width: 640.5"), "image_width: \"640.5\" is not an integer" },
		{ replaced(ros, "701.12345", "0.0"), "camera: fx must be positive" },
		{ replaced(ros, "1.     ]", "2.     ]"), "last row" },
		{ replaced(ros, "[1., 0., 0.,", "[1., 0., 0.,["), "a [ or { that does not close" },
		{ replaced(ros, "  rows: 3\n  cols: 3\n  data: [ 701", "  rows: 3\n\tcols: 3\n  data: [ 701"), "tab" },
		{ ros + "camera_matrix: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n", "key camera_matrix given twice" },
		{ replaced(ros, "image_width: 640", "image_width: &w 640"), "anchors and aliases" },
		{ replaced(ros, "  rows: 3\n  cols: 3\n  data: [ 701", "  rows: 3\n    cols: 3\n  data: [ 701"),
		  "line 6: unexpected indentation" },
		{ "imageSize: [640, 480, 3]\nK: [1, 0, 0, 0, 1, 0, 0, 0, 1]\nD: []\n", "imageSize: 3 numbers, expected 2" },
		{ "K: " + std::string(100, '[') + std::string(100, ']') + "\n", "nested deeper than 32" },
		{ replaced(xml, "opencv_storage>\n<calib", "calibration>\n<calib"), "<calibration> closed by </opencv_storage>" },
		{ replaced(replaced(xml, "<opencv_storage>", "<calibration>"), "</opencv_storage>", "</calibration>"),
		  "<calibration>: not an OpenCV FileStorage file" },
		{ replaced(xml, "<dt>d</dt>", "<dt>u</dt>"), "camera_matrix: dt \"u\", expected d or f" },
		{ replaced(xml, "<cols>3</cols>", "<cols>3</rows>"), "<cols> closed by </rows>" },
		{ replaced(xml, "0. 0. 1.</data>", "0. 0. 1. &nbsp;</data>"), "unknown entity &nbsp;" },
		{ replaced(xml, "<?xml version=\"1.0\"?>", "<!DOCTYPE x [<!ENTITY a \"b\">]>"), "DOCTYPE" },
		{ "just some text\n", "expected key: value" },
		{ "  \n\n", "empty" },
		{ "[1, 2, 3]\n", "line 1: expected key: value, got \"[1, 2, 3]\"" },
		{ "- 1\n- 2\n", "not a calibration file" },
		{ std::string("K: [1, 0, 0\0, 0]", 16), "NUL" },
	};
	int i = 0;
	for (const auto &c : cases) {
		const std::string e = errorOf(c.text);
		EXPECT_EQ(e.rfind("cam.yaml: ", 0), 0u) << "case " << i << ": " << e;
		EXPECT_NE(e.find(c.mention), std::string::npos) << "case " << i << ": " << e;
		++i;
	}
}

TEST(Calibration, UnreadableFilesAreRuntimeErrors)
{
	const Scratch scratch;
	EXPECT_THROW(readCalibration((scratch.dir / "missing.yaml").string()), std::runtime_error);
	EXPECT_THROW(readCalibration(scratch.dir.string()), std::runtime_error);
	const std::string big = scratch.write("big.yaml", std::string(kRos) + "# " + std::string(1 << 20, 'x') + "\n");
	try {
		readCalibration(big);
		FAIL() << "a file over 1 MiB was read";
	} catch (const std::runtime_error &e) {
		EXPECT_NE(std::string(e.what()).find("1 MiB"), std::string::npos) << e.what();
		EXPECT_EQ(dynamic_cast<const std::invalid_argument *>(&e), nullptr);
	}
	EXPECT_THROW(parseCalibration(std::string(kRos) + "# " + std::string(1 << 20, 'x'), "big"),
		     std::invalid_argument);
	/* A file read is parsed; its messages name its path. */
	const std::string ok = scratch.write("ost.yaml", kRos);
	EXPECT_EQ(readCalibration(ok).matrix[0], 701.12345);
	const std::string bad = scratch.write("bad.yaml", replaced(kRos, "cols: 5", "cols: 6"));
	try {
		readCalibration(bad);
		FAIL();
	} catch (const std::invalid_argument &e) {
		EXPECT_EQ(std::string(e.what()).rfind(bad + ": distortion_coefficients: ", 0), 0u) << e.what();
	}
}

/* Issue 34: a name replaced by a FIFO (between any check and the open)
 * blocked the open forever; a device was read without end. What is opened
 * is checked, without waiting. */
TEST(Calibration, FifoOrDeviceIsRefusedWithoutWaiting)
{
	const Scratch scratch;
	const std::string fifo = (scratch.dir / "cam.yaml").string();
	EXPECT_EQ(frappe::test::readingFifo(fifo, [](const std::string &p) { readCalibration(p); }),
		  fifo + ": not a regular file (a FIFO)");
	EXPECT_FALSE(frappe::test::blockedBySwappedFifo((scratch.dir / "swapped.yaml").string(), kRos, 1.0,
							 [](const std::string &p) { readCalibration(p); }));
	try {
		readCalibration("/dev/zero");
		FAIL() << "/dev/zero read";
	} catch (const std::runtime_error &e) {
		EXPECT_EQ(std::string(e.what()), "/dev/zero: not a regular file (a character device)");
	}
	try {
		readCalibration(scratch.dir.string());
		FAIL() << "a directory read";
	} catch (const std::runtime_error &e) {
		EXPECT_EQ(std::string(e.what()), scratch.dir.string() + ": not a regular file (a directory)");
	}
}

/* Issue 34: messages quote the file's name and values; both may be any
 * bytes, the message is UTF-8 (a byte that is not, read as Latin-1). */
TEST(Calibration, MessagesAreUtf8WhateverTheInput)
{
	EXPECT_EQ(errorOf(replaced(kRos, "plumb_bob", "caf\xe9"), "cam\xff.yaml"),
		  "cam\xc3\xbf.yaml: distortion_model: \"caf\xc3\xa9\" is unknown: expected plumb_bob or rational_polynomial");
}

/* The files shipped for the sample video: the camera it was rendered with. */
TEST(Calibration, SampleVideoFiles)
{
	const std::string dir = std::string(FRAPPE_SOURCE_ROOT) + "/examples/data/";
	const Camera ros = readCalibration(dir + "camera-700.yaml");
	const Camera cv = readCalibration(dir + "camera-700-opencv.yml");
	for (const Camera &c : { ros, cv }) {
		EXPECT_EQ(c.width, 640);
		EXPECT_EQ(c.height, 480);
		expectMatrix(c, { 700, 0, 319.5, 0, 700, 239.5, 0, 0, 1 });
		EXPECT_EQ(c.distortion, std::vector<double>(5, 0.0));
	}
}
