"""epichead.Sequence, Camera, Model and the pose CSVs on the real teabox sequence."""
import numpy as np
import pytest

import epichead


def test_sequence_reads_camera_model_init_and_frames(teabox):
    cam = teabox.camera
    assert (cam.width, cam.height) == (640, 480)
    assert cam.K.shape == (3, 3) and cam.K[2, 2] == 1
    model = teabox.model
    assert model.vertices.shape == (8, 3)
    assert len(model.edges) == 12 and model.closed
    assert all(0 <= a < 8 and 0 <= b < 8 for a, b in model.edges)
    assert teabox.init is not None and teabox.init.frame == 0
    pose = teabox.init.pose
    assert pose.shape == (4, 4)
    np.testing.assert_allclose(pose[:3, :3] @ pose[:3, :3].T, np.eye(3), atol=1e-9)
    assert 0.3 < pose[2, 3] < 0.6  # the box is about 45 cm in front of the camera
    assert len(teabox) == len(teabox.frames) == 39  # video.mp4 at 25 fps
    assert teabox.frames[1].t_s == pytest.approx(0.04)
    assert teabox.ground_truth == [] and teabox.imu.shape == (0, 7)


def test_read_frame_gives_the_cameras_size_in_bgr(teabox):
    image = teabox.read_frame(0)
    assert image.dtype == np.uint8 and image.shape == (480, 640, 3)
    assert image.std() > 10  # a picture, not a blank


def test_frames_beyond_the_sequence_raise_index_error(teabox):
    with pytest.raises(IndexError):
        teabox.read_frame(len(teabox))


def test_camera_projects_and_unprojects_as_inverse_maps(teabox):
    cam = teabox.camera
    points = np.array([[0.0, 0.0, 1.0], [0.1, -0.05, 0.5], [-0.2, 0.1, 2.0]])
    px = cam.project(points)
    assert px.shape == (3, 2)
    assert not any(cam.distortion)  # the teabox's calibration: the optical axis meets the principal point
    np.testing.assert_allclose(px[0], cam.K[:2, 2], atol=1e-9)
    rays = cam.unproject(px)
    np.testing.assert_allclose(rays, points / points[:, 2:3], atol=1e-6)


def test_camera_save_and_load_round_trip(teabox, tmp_path):
    path = tmp_path / "camera.yaml"
    teabox.camera.save(str(path))
    again = epichead.Camera.load(str(path))
    np.testing.assert_allclose(again.K, teabox.camera.K)
    assert again.distortion == teabox.camera.distortion


def test_pose_csv_round_trip(teabox, tmp_path):
    poses = [epichead.StampedPose(i, 0.04 * i, teabox.init.pose, "tracked") for i in range(3)]
    path = tmp_path / "poses.csv"
    epichead.write_pose_csv(str(path), poses)
    back = epichead.read_pose_csv(str(path))
    assert [p.frame for p in back] == [0, 1, 2]
    assert back[2].status == "tracked"
    np.testing.assert_allclose(back[1].pose, teabox.init.pose, atol=1e-8)


def test_model_loads_from_its_file(teabox_dir):
    model = epichead.Model.load(str(teabox_dir / "model.cao"))
    assert model.vertices.shape == (8, 3) and len(model.faces) == 6
