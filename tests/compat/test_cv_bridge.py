"""cv_bridge: upstream's test cases (vision_opencv cv_bridge/test/*.py) restated, and conversions checked."""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

import aiorobot.msgs as msgs
from aiorobot.compat.cv_bridge import CvBridge, CvBridgeError, getCvType
from aiorobot.msgs.sensor_msgs import CompressedImage, Image
from aiorobot.msgs.std_msgs import Header

from ._run import Program

_DEPTHS = [np.uint8, np.int8, np.uint16, np.int16, np.int32, np.float32, np.float64]


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(26)


def test_an_8uc3_image_cannot_become_mono16_but_an_rgb8_one_can(rng) -> None:
    # upstream test_mono16_cv2
    br = CvBridge()
    im = rng.integers(0, 255, size=(48, 64, 3), dtype=np.uint8)
    with pytest.raises(CvBridgeError, match=r"^\[8UC3\] is not a color format. but \[mono16\] is"):
        br.imgmsg_to_cv2(br.cv2_to_imgmsg(im), "mono16")
    mono16 = br.imgmsg_to_cv2(br.cv2_to_imgmsg(im, "rgb8"), "mono16")
    expected = cv2.cvtColor(im, cv2.COLOR_RGB2GRAY).astype(np.float64) * 65535 / 255
    assert mono16.dtype == np.uint16 and mono16.shape == (48, 64)
    np.testing.assert_array_equal(mono16, np.rint(expected).astype(np.uint16))


@pytest.mark.parametrize("depth", _DEPTHS)
@pytest.mark.parametrize("channels", [None, 1, 2, 3, 4, 5])
def test_every_depth_and_channel_count_round_trips(rng, depth, channels) -> None:
    # upstream test_encode_decode_cv2 (there for sizes 100..700; two odd sizes here)
    for h, w in ((7, 13), (100, 300)):
        shape = (h, w) if channels is None else (h, w, channels)
        original = rng.integers(0, 127, size=shape).astype(depth)
        msg = CvBridge().cv2_to_imgmsg(original)
        new = CvBridge().imgmsg_to_cv2(msg)
        assert new.dtype == original.dtype
        assert new.shape == (original.shape[:2] if channels == 1 else original.shape)
        np.testing.assert_array_equal(new.reshape(original.shape), original)
        assert msg.step == w * (channels or 1) * np.dtype(depth).itemsize


@pytest.mark.parametrize("fmt", ["jpg", "jpeg", "jpe", "png", "bmp", "dib", "sr", "ras", "tif", "tiff"])
def test_compressed_images_round_trip_in_every_format(rng, fmt) -> None:
    # upstream test_encode_decode_cv2_compressed
    for channels in (None, 1, 3):
        shape = (60, 80) if channels is None else (60, 80, channels)
        original = rng.integers(0, 255, size=shape, dtype=np.uint8)
        msg = CvBridge().cv2_to_compressed_imgmsg(original, fmt)
        assert msg.format == fmt
        new = CvBridge().compressed_imgmsg_to_cv2(msg)
        assert new.dtype == original.dtype
        assert new.shape == (original.shape[:2] if channels == 1 else original.shape)
        if fmt in ("png", "bmp", "dib", "tif", "tiff"):  # lossless: the image comes back (upstream checks only shapes)
            np.testing.assert_array_equal(new.reshape(original.shape), original)


def test_a_big_endian_image_is_flagged_and_read_back(rng) -> None:
    # upstream test_endianness
    br = CvBridge()
    img = rng.integers(0, 255, size=(30, 40))
    msg = br.cv2_to_imgmsg(img.astype(np.dtype("int32").newbyteorder(">")))
    assert msg.is_bigendian
    assert msg.encoding == "32SC1"
    out = br.imgmsg_to_cv2(msg)
    assert (out == img).all() and out.dtype.isnative


def test_rgba8_data_converts_and_a_3_channel_image_is_no_rgba8() -> None:
    # upstream test_enumerants_cv2 and test_numpy_types
    msg = Image(width=640, height=480, encoding="rgba8", step=640 * 4)
    msg.data = ((640 * 480) * "1234").encode()
    br = CvBridge()
    cvim = br.imgmsg_to_cv2(msg, "rgb8")
    assert cvim.shape == (480, 640, 3) and (cvim[0, 0] == [ord("1"), ord("2"), ord("3")]).all()
    with pytest.raises(CvBridgeError, match=r"^encoding specified as rgba8, but image has incompatible type 8UC3$"):
        br.cv2_to_imgmsg(cvim, "rgba8")
    assert br.cv2_to_imgmsg(cvim, "rgb8").encoding == "rgb8"
    assert br.cv2_to_imgmsg(cvim, "bgr8").encoding == "bgr8"
    assert getCvType("32FC4") != cv2.CV_8UC4
    assert getCvType("8UC1") == cv2.CV_8UC1
    assert getCvType("8U") == cv2.CV_8UC1
    assert getCvType("bgr8") == cv2.CV_8UC3 and getCvType("mono16") == cv2.CV_16UC1
    with pytest.raises(TypeError, match="Your input type is not a numpy array"):
        br.cv2_to_imgmsg(1, "rgba8")


def test_mono8_keeps_its_two_dimensional_shape(rng) -> None:
    # upstream python_bindings.py
    br = CvBridge()
    mono = (rng.random((100, 100)) * 255).astype(np.uint8)
    out = br.imgmsg_to_cv2(br.cv2_to_imgmsg(mono, encoding="mono8"), desired_encoding="mono8")
    assert out.shape == (100, 100)


@pytest.mark.parametrize(("src", "dst", "code"), [
    ("rgb8", "bgr8", cv2.COLOR_RGB2BGR), ("bgr8", "mono8", cv2.COLOR_BGR2GRAY),
    ("rgba8", "bgr8", cv2.COLOR_RGBA2BGR), ("mono8", "rgb8", cv2.COLOR_GRAY2RGB),
    ("bayer_rggb8", "bgr8", cv2.COLOR_BayerBG2BGR), ("bayer_grbg8", "mono8", cv2.COLOR_BayerGB2GRAY),
    ("yuv422", "rgb8", cv2.COLOR_YUV2RGB_UYVY), ("yuv422_yuy2", "bgr8", cv2.COLOR_YUV2BGR_YUY2),
])
def test_colour_conversions_are_opencvs(rng, src, dst, code) -> None:
    br = CvBridge()
    channels = {"rgb8": 3, "bgr8": 3, "rgba8": 4, "mono8": 1}.get(src, 2 if "yuv" in src else 1)
    shape = (8, 12) if channels == 1 else (8, 12, channels)
    im = rng.integers(0, 255, size=shape, dtype=np.uint8)
    out = br.imgmsg_to_cv2(br.cv2_to_imgmsg(im, src), dst)
    np.testing.assert_array_equal(out, cv2.cvtColor(im, code))


def test_depth_changes_scale_between_8_and_16_bits_and_keep_other_depths(rng) -> None:
    br = CvBridge()
    mono8 = np.array([[0, 1, 128, 255]], dtype=np.uint8)
    mono16 = br.imgmsg_to_cv2(br.cv2_to_imgmsg(mono8, "mono8"), "mono16")
    np.testing.assert_array_equal(mono16, [[0, 257, 32896, 65535]])
    back = br.imgmsg_to_cv2(br.cv2_to_imgmsg(mono16, "mono16"), "mono8")
    np.testing.assert_array_equal(back, mono8)
    bgr16 = br.imgmsg_to_cv2(br.cv2_to_imgmsg(np.dstack([mono8] * 3), "rgb8"), "bgr16")
    assert bgr16.dtype == np.uint16 and bgr16[0, 3].tolist() == [65535] * 3
    # a generic encoding to a same-channel one converts the values, unscaled
    depth = rng.random((4, 5)).astype(np.float32) * 10
    as64 = br.imgmsg_to_cv2(br.cv2_to_imgmsg(depth), "64FC1")
    assert as64.dtype == np.float64
    np.testing.assert_array_equal(as64, depth.astype(np.float64))
    with pytest.raises(CvBridgeError, match=r"^\[32FC1\] and \[32FC3\] do not have the same number of channel$"):
        br.imgmsg_to_cv2(br.cv2_to_imgmsg(depth), "32FC3")
    with pytest.raises(CvBridgeError, match=r"^\[rgb8\] is a color format but \[32FC1\] is not"):
        br.imgmsg_to_cv2(br.cv2_to_imgmsg(np.zeros((2, 2, 3), np.uint8), "rgb8"), "32FC1")
    with pytest.raises(CvBridgeError, match=r"^Unsupported conversion from \[mono8\] to \[yuv422\]$"):
        br.imgmsg_to_cv2(br.cv2_to_imgmsg(mono8, "mono8"), "yuv422")


def test_rows_padded_past_the_width_and_big_endian_16_bit_data_are_read() -> None:
    # a 2x3 mono16 image, big endian, rows padded to 8 bytes (as some drivers send)
    values = np.array([[1, 2, 3], [256, 65535, 4]], dtype=">u2")
    rows = [values[r].tobytes() + b"\xee\xee" for r in range(2)]
    msg = Image(height=2, width=3, encoding="mono16", is_bigendian=True, step=8, data=np.frombuffer(b"".join(rows), np.uint8))
    out = CvBridge().imgmsg_to_cv2(msg)
    assert out.dtype == np.dtype("uint16") and out.dtype.isnative
    np.testing.assert_array_equal(out, values.astype(np.uint16))


def test_bad_messages_and_encodings_raise_cv_bridge_errors() -> None:
    br = CvBridge()
    with pytest.raises(CvBridgeError, match=r"^Unrecognized image encoding \[jpeg\]$"):
        br.imgmsg_to_cv2(Image(height=1, width=1, encoding="jpeg", step=1, data=[0]))
    with pytest.raises(CvBridgeError, match=r"^Image is wrongly formed: height \* step != size  or  2 \* 3 != 3$"):
        br.imgmsg_to_cv2(Image(height=2, width=3, encoding="mono8", step=3, data=[0, 0, 0]))
    with pytest.raises(CvBridgeError, match=r"image dtype int64 has no OpenCV depth; expected one of uint8"):
        br.cv2_to_imgmsg(np.zeros((2, 2), np.int64))
    with pytest.raises(CvBridgeError, match=r"cannot decode the compressed image \(3 bytes, format 'png'\)"):
        br.compressed_imgmsg_to_cv2(CompressedImage(format="png", data=[1, 2, 3]))
    with pytest.raises(CvBridgeError, match=r"cannot encode the image as 'nope'"):
        br.cv2_to_compressed_imgmsg(np.zeros((4, 4), np.uint8), "nope")
    assert issubclass(CvBridgeError, TypeError)


def test_messages_carry_the_header_and_survive_cdr(rng) -> None:
    header = Header(frame_id="camera_optical_frame")
    header.stamp.sec = 12
    im = rng.integers(0, 255, size=(6, 5, 3), dtype=np.uint8)
    msg = CvBridge().cv2_to_imgmsg(im, "bgr8", header=header)
    assert msg.header == header
    again = msgs.deserialize(msgs.serialize(msg), Image)
    np.testing.assert_array_equal(CvBridge().imgmsg_to_cv2(again, "rgb8"), im[:, :, ::-1])
    cmsg = msgs.deserialize(msgs.serialize(CvBridge().cv2_to_compressed_imgmsg(im, "png")), CompressedImage)
    np.testing.assert_array_equal(CvBridge().compressed_imgmsg_to_cv2(cmsg, "rgb8"), im[:, :, ::-1])


def test_a_program_imports_cv_bridge_under_aiorobot_exec(tmp_path: Path) -> None:
    script = tmp_path / "perception.py"
    script.write_text(
        "import numpy as np\n"
        "from cv_bridge import CvBridge, CvBridgeError\n"
        "from sensor_msgs.msg import Image\n"
        "msg = CvBridge().cv2_to_imgmsg(np.full((4, 6, 3), 7, np.uint8), 'rgb8')\n"
        "print(type(msg) is Image, CvBridge().imgmsg_to_cv2(msg, 'mono8').shape)\n"
        "from cv_bridge import cvtColorForDisplay\n"
    )
    program = Program(str(script))
    assert program.finish() == 1
    assert program.lines[0] == "True (4, 6)"
    assert program.lines[1].startswith(f"aiorobot exec: {script}:6: aiorobot does not provide cv_bridge.cvtColorForDisplay yet")
    assert len(program.lines) == 2
