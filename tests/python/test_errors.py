"""Bad input gives a Python exception (epichead.Error, a ValueError) naming the file: never a crash."""
import numpy as np
import pytest

import epichead


def test_error_is_a_value_error():
    assert issubclass(epichead.Error, ValueError)


def test_missing_files_are_named(tmp_path):
    missing = str(tmp_path / "nothing_here")
    for load in (epichead.Camera.load, epichead.Model.load, epichead.Sequence, epichead.read_pose_csv, epichead.replay):
        with pytest.raises(epichead.Error, match="nothing_here"):
            load(missing)


def test_malformed_files_say_file_and_line(tmp_path):
    cao = tmp_path / "broken.cao"
    cao.write_text("V1\n3\n0 0 0\n1 0 nonsense\n")
    with pytest.raises(epichead.Error, match=r"broken\.cao:\d+"):
        epichead.Model.load(str(cao))
    poses = tmp_path / "poses.csv"
    poses.write_text("frame,t_s,tx,ty,tz,qw,qx,qy,qz\n0,0,0,0,1,1,0,0\n")
    with pytest.raises(epichead.Error, match=r"poses\.csv:2"):
        epichead.read_pose_csv(str(poses))
    cam = tmp_path / "camera.yaml"
    cam.write_text("%YAML:1.0\n---\nimage_width: 640\n")
    with pytest.raises(epichead.Error, match="camera.yaml"):
        epichead.Camera.load(str(cam))
    log = tmp_path / "not_a_log.txt"
    log.write_text("hello\nworld\n")
    with pytest.raises(epichead.Error, match="not_a_log.txt"):
        epichead.replay(str(log))
    dbc = tmp_path / "empty.dbc"
    dbc.write_text("VERSION \"\"\n")
    with pytest.raises(epichead.Error, match="empty.dbc"):
        epichead.replay(str(log), dbc=[str(dbc)])


def test_bad_images_and_poses_raise(teabox):
    tracker = epichead.Tracker(teabox.camera, teabox.model)
    pose = teabox.init.pose
    with pytest.raises(epichead.Error, match="640x480"):
        tracker.track(np.zeros((100, 100, 3), np.uint8), pose)
    with pytest.raises(epichead.Error, match="channels"):
        tracker.track(np.zeros((480, 640, 2), np.uint8), pose)
    with pytest.raises(epichead.Error, match="dimensions"):
        tracker.track(np.zeros(480 * 640, np.uint8), pose)
    with pytest.raises(epichead.Error, match="rigid"):
        tracker.track(np.zeros((480, 640), np.uint8), np.ones((4, 4)))
    with pytest.raises(epichead.Error, match="NaN"):
        tracker.track(np.zeros((480, 640), np.uint8), np.full((4, 4), np.nan))
    with pytest.raises(TypeError):
        tracker.track(np.zeros((480, 640), np.uint8), np.eye(3))
    # A blank frame is not an error: the object is simply not found.
    assert tracker.track(np.zeros((480, 640), np.uint8), pose).status == "lost"


def test_bad_options_raise():
    with pytest.raises(epichead.Error, match="mode"):
        epichead.Predictor(mode="kalman")
    with pytest.raises(epichead.Error, match="imu_protocol"):
        epichead.replay("/dev/null", imu_protocol="morse")
    with pytest.raises(epichead.Error, match="bitrate"):
        epichead.replay("/dev/null", bitrate=0)
    with pytest.raises(ValueError):
        epichead.Camera(0, 480, 500, 500, 320, 240)


def test_bad_tracker_mode_raises(teabox):
    with pytest.raises(epichead.Error, match="epic\\+validation"):
        epichead.Tracker(teabox.camera, teabox.model, mode="fast")


def test_non_finite_imu_is_rejected_not_fatal():
    p = epichead.Predictor()
    assert p.add_imu(0.0, np.array([np.nan, 0, 0]), np.zeros(3)) == "non-finite"
    verdict, _ = p.add_vision(0.0, np.eye(4), np.full((6, 6), np.nan))
    assert verdict == "bad-input"


def test_distortion_lists_as_opencv_writes_them():
    # 5 and 8 coefficients take OpenCV's order, the rest zero; a count OpenCV never writes is refused.
    five = epichead.Camera(640, 480, 500, 500, 320, 240, [0.1, -0.02, 0.001, 0.002, 0.003])
    assert list(five.distortion[:5]) == [0.1, -0.02, 0.001, 0.002, 0.003] and not any(five.distortion[5:])
    eight = epichead.Camera(640, 480, 500, 500, 320, 240, [0.1, -0.02, 0, 0, 0, 0.05, 0.01, 0.002])
    assert eight.distortion[5] == 0.05
    with pytest.raises(epichead.Error, match="3"):
        epichead.Camera(640, 480, 500, 500, 320, 240, [0.1, 0.2, 0.3])
