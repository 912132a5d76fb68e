"""Hypothesis fuzz of the node strings a Supervisor hands the server, on the sans-IO core (tests/worlds/
contact_points.wbt): importMFNodeFromString of node text taken from the world's own exportString and then
cut, spliced with huge, tiny, NaN and infinite numbers, nested deeper than allowed or left unterminated.
Every request gets one reply; a refusal is one line with a protocol code other than INTERNAL; an import
that is taken exports as text again, and the world keeps answering (a step, the contact points and
balance of the first box). A world file whose bounding object's volume overflows (a sphere of radius 1e308)
is refused at load in lines naming where, not with an OverflowError or a numpy warning; a joint ending in a
SolidReference is one load line saying what it names (a Solid, the static environment, nothing, a name no
Solid bears)."""

from __future__ import annotations

import math

import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS, Fuzzed
from test_fuzz_new_devices import send

from sensorium.server.world.loader import WorldError, load_world

R = "/sup/robot/"


def fresh() -> tuple[Fuzzed, int, str]:
    """A new core, the first box's id and its exportString."""
    f = Fuzzed("contact_points.wbt", copied=True)
    [reply] = send(f, "attach", {"robot": "sup"})
    assert reply["ok"], reply
    box = send(f, R + "get_from_def", {"name": "BOX"})[0]["result"]["node"]
    [reply] = send(f, R + "node_export_string", {"node": box})
    return f, box, reply["result"]["value"]


TEXT = fresh()[2]
numbers = st.sampled_from(["1e308", "-1e308", "1e309", "1e-320", "nan", "NaN", "inf", "-inf", "0x7fffffff",
                           "99999999999999999999999", "-0", "1e-31", "1e9", "1.0000000001e9", "+.5", "1e", "--1"])
nodes = st.sampled_from(["Box { size 1e308 1e308 1e308 }", "Sphere { radius 1e308 }", "Sphere { radius 1e200 }",
                         "Capsule { radius 1e300 height 1e300 }", "Cylinder { radius 1e200 height 1 }",
                         "Box { size 1e-300 1 1 }", "Sphere { radius 1e-320 }", "Box { size 0 0 0 }"])


@st.composite
def node_strings(draw) -> str:
    text = TEXT
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.integers(0, 4))
        at = draw(st.integers(0, len(text)))
        if kind == 0:          # cut: unterminated
            text = text[:at]
        elif kind == 1:        # a number replaced
            words = text.split(" ")
            k = draw(st.integers(0, len(words) - 1))
            words[k] = draw(numbers)
            text = " ".join(words)
        elif kind == 2:        # a bounding object of extreme size, with Physics weighing it
            text = (f'Solid {{ name "{draw(st.sampled_from(["a", "b"]))}" boundingObject {draw(nodes)} '
                    f'physics Physics {{ {draw(st.sampled_from(["", "density 1e300", "mass 1e9"]))} }} }}')
        elif kind == 3:        # nested deeper than the parser takes, closed or not
            depth = draw(st.sampled_from([99, 100, 101, 2000]))
            tail = " ] }" * depth if draw(st.booleans()) else ""
            text = "Solid { children [ " + "Pose { children [ " * depth + tail + " ] }"
        else:                  # a character in
            text = text[:at] + draw(st.sampled_from(["{", "}", "[", "]", '"', "\0", "\\", "#", "\n", "é", "USE X "])) + text[at:]
    return text


@pytest.mark.parametrize("examples", example_counts(300))
def test_imported_node_strings_are_taken_or_refused_in_one_line(examples: int) -> None:
    f, box, _ = fresh()

    @settings(SETTINGS, max_examples=examples)
    @given(node_strings(), st.sampled_from([0, -1, 1, -(1 << 31)]))
    def run(text, position):
        [reply] = send(f, R + "import_node_from_string", {"node": 0, "field": "children", "position": position,
                                                          "node_string": text})
        if reply["ok"]:
            for node in reply["result"]["value"]:
                [exported] = send(f, R + "node_export_string", {"node": node})
                assert exported["ok"] and isinstance(exported["result"]["value"], str), exported
                [removed] = send(f, R + "remove_node", {"node": node})
                assert removed["ok"], removed
        else:
            message = reply["error"]["message"]
            assert "\n" not in message and "Traceback" not in message and "Error:" not in message[:40], message
        f.assert_healthy()
        f.steps()
        [points] = send(f, R + "get_node_contact_points", {"node": box})
        assert points["ok"] and all(math.isfinite(v) for v in points["result"]["points"]), points
        [balance] = send(f, R + "get_node_static_balance", {"node": box})
        assert balance["ok"] and isinstance(balance["result"]["value"], bool), balance
        f.assert_healthy()

    run()


@pytest.mark.filterwarnings("error::RuntimeWarning")       # (inf * 0 in the centroid: no warning on stderr either)
@pytest.mark.parametrize("bounding", ["Sphere { radius 1e308 }", "Capsule { radius 1e308 height 1 }",
                                      "Box { size 1e300 1e300 1e300 }"])
def test_a_bounding_object_whose_volume_overflows_is_refused_where_it_is(tmp_path, bounding: str) -> None:
    path = tmp_path / "w.wbt"
    path.write_text(f"#VRML_SIM R2023b utf8\nSolid {{ boundingObject {bounding} physics Physics {{ }} }}\n")
    with pytest.raises(WorldError) as info:
        load_world(path)
    lines = str(info.value).splitlines()
    assert lines and all(line.startswith(f"{path}: line 2, column ") for line in lines), lines
    assert any("solids[0].mass.kg): expected a finite number, got inf" in line for line in lines), lines


@pytest.mark.parametrize(("reference", "line"), [
    ('solidName "finger"', "HingeJoint ending in SolidReference 'finger': the loop it closes is not closed here "
                           "(no physics); 'finger' moves with the joints it is written in only"),
    ('solidName "<static environment>"', "HingeJoint ending in SolidReference '<static environment>': the Solid "
                                         "above it is not tied to the world here (no physics); the joint is left out"),
    ("", "HingeJoint ending in a SolidReference without a solidName: it names no Solid; the joint is left out"),
    ('solidName "a\\"b\\nc"', "HingeJoint ending in SolidReference 'a\"bnc': the loop it closes is not closed here "
                              "(no physics); 'a\"bnc' moves with the joints it is written in only"),
    # no Solid of the robot bears the name (Webots refuses the reference)
    ('solidName "fingers"', "HingeJoint ending in SolidReference 'fingers': no Solid is named 'fingers' in the robot "
                            "or solid it is written in (Webots refuses the reference); the joint is left out")])
def test_a_joint_ending_in_a_solid_reference_is_one_load_line_saying_what_it_ties(tmp_path, reference: str,
                                                                                  line: str) -> None:
    # Webots' solidName: a Solid's name, or <static environment> (the Solid above the joint tied to the world)
    path = tmp_path / "w.wbt"
    robot = ('Robot { name "arm" children [ HingeJoint { endPoint Solid { name "link" children [ Solid { name "finger" } '
             'Solid { name "a\\"b\\nc" } RotationalMotor { name "fingers" } '
             f'HingeJoint {{ endPoint SolidReference {{ {reference} }} }} ] }} }} ] }}\n')
    path.write_text("#VRML_SIM R2023b utf8\n" + robot)
    warnings = [w for w in load_world(path).warnings if "SolidReference" in w]
    assert warnings == [f"{path}:2:{robot.rindex('HingeJoint') + 1}: {line}"], warnings


@pytest.mark.parametrize(("name", "says"), [("grip", "whose loop is not closed here"), ("grips", "which names no Solid")])
def test_a_motor_on_a_joint_ending_in_a_solid_reference_says_whether_it_names_a_solid(tmp_path, name: str,
                                                                                      says: str) -> None:
    path = tmp_path / "w.wbt"
    robot = ('Robot { name "arm" children [ Solid { name "grip" } HingeJoint { device [ RotationalMotor { name "m" } ] '
             f'endPoint SolidReference {{ solidName "{name}" }} }} ] }}\n')
    path.write_text("#VRML_SIM R2023b utf8\n" + robot)
    motor = [w for w in load_world(path).warnings if "motor 'm'" in w]
    assert motor == [f"{path}:2:{robot.index('HingeJoint') + 1}: HingeJoint motor 'm' is no wheel (its end point has no "
                     "cylinder or sphere to roll on): its joint moves kinematically (Webots' rule without physics; its "
                     f"PositionSensor reads it), but moves nothing: its end point is SolidReference '{name}', {says}"], motor
