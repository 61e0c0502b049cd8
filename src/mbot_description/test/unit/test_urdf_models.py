"""The two URDFs: check_urdf accepts them, every body has an inertial, the frames follow
docs/ARCHITECTURE.md (names and frames)."""
import math
import os
import subprocess
import xml.etree.ElementTree as ET

import pytest

from paths import MODELS, URDF_DIR


def load(model):
    return ET.parse(os.path.join(URDF_DIR, model + ".urdf")).getroot()


@pytest.mark.parametrize("model", MODELS)
def test_check_urdf_accepts(model):
    path = os.path.join(URDF_DIR, model + ".urdf")
    result = subprocess.run(["check_urdf", path], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "robot name is: " + model in result.stdout
    assert "root Link: base_footprint" in result.stdout


@pytest.mark.parametrize("model", MODELS)
def test_every_body_has_mass_and_inertia(model):
    links = load(model).findall("link")
    # Frames (no geometry: base_footprint, imu_link) are not bodies and carry no inertial.
    bodies = [link for link in links if link.find("visual") is not None or link.find("collision") is not None]
    frames = [link for link in links if link not in bodies]
    assert all(link.find("inertial") is None for link in frames)
    assert len(bodies) >= 4
    for link in bodies:
        inertial = link.find("inertial")
        assert inertial is not None, link.get("name")
        assert float(inertial.find("mass").get("value")) > 0.0, link.get("name")
        inertia = inertial.find("inertia")
        for axis in ("ixx", "iyy", "izz"):
            assert float(inertia.get(axis)) > 0.0, (link.get("name"), axis)
    # base_footprint is a frame on the ground, not a body (KDL ignores a root link's inertia).
    footprint = [link for link in links if link.get("name") == "base_footprint"]
    assert len(footprint) == 1 and footprint[0].find("inertial") is None


@pytest.mark.parametrize("model", MODELS)
def test_frame_chain_of_design_md(model):
    joints = {j.find("child").get("link"): j for j in load(model).findall("joint")}
    assert joints["base_link"].find("parent").get("link") == "base_footprint"
    assert joints["base_laser"].find("parent").get("link") == "base_link"
    assert joints["base_laser"].get("type") == "fixed"
    wheels = [j for j in joints.values() if j.get("type") == "continuous"]
    assert len(wheels) == (2 if model == "mbot" else 4)
    for wheel in wheels:
        assert wheel.find("parent").get("link") == "base_link"
        # the wheel touches the ground: base_link height + joint z == wheel radius
        base_z = float(joints["base_link"].find("origin").get("xyz").split()[2])
        wheel_z = float(wheel.find("origin").get("xyz").split()[2])
        child = load(model).find("link[@name='%s']" % wheel.find("child").get("link"))
        radius = float(child.find("collision/geometry/cylinder").get("radius"))
        assert math.isclose(base_z + wheel_z, radius, abs_tol=1e-9)
