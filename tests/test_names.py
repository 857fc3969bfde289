"""An unknown name (task, suite, method, algorithm, tag) is said one way everywhere: the name,
the closest known ones, every known one, on one line, unquoted."""

import gymnasium as gym
import pytest

import craftsuite
from craftsuite.hyperparameters import HyperparameterError, check_hyperparameters, hyperparameter_examples
from craftsuite.methods import check_methods
from craftsuite.names import UnknownName, closest, unknown_name, unknown_text
from craftsuite.suites import suite_named
from craftsuite.task_registry import resolve_task


def test_the_message_names_the_closest_and_every_known_name():
    err = unknown_name("task", "ToolHme", ["Reach", "ToolHome", "TwoToolsHome"], "(or a spec file)")
    assert str(err) == ("unknown task 'ToolHme' (did you mean ToolHome or TwoToolsHome?); "
                        "tasks: Reach, ToolHome, TwoToolsHome (or a spec file)")
    assert isinstance(err, KeyError) and isinstance(err, ValueError)  # callers catching either keep working
    assert str(unknown_name("suite", "zzz", ["quick", "hard"])) == "unknown suite 'zzz'; suites: quick, hard"


def test_several_names_each_get_their_suggestion():
    err = unknown_name("method", ["dqnn", "zzz"], ["dqn", "crm"])
    assert str(err) == "unknown methods 'dqnn' (did you mean dqn?), 'zzz'; methods: dqn, crm"
    assert str(unknown_name("bus", "x", ["y"], plural="buses")) == "unknown bus 'x'; buses: y"


def test_a_list_is_several_names_and_anything_else_one():
    assert str(unknown_name("task", ("Reach",), ["Reach"])).startswith("unknown task ('Reach',) ")
    assert unknown_text("key", ["b", "a"], ["c"]) == "unknown keys 'b', 'a'; keys: c"  # in the order given


def test_callers_catching_key_or_value_errors_still_catch_them():
    for error in (KeyError, ValueError):
        with pytest.raises(error):
            resolve_task("Nope")
        with pytest.raises(error):
            suite_named("nope")


def test_a_misspelt_setting_or_keyword_gets_its_suggestion_too():
    with pytest.raises(HyperparameterError, match=r"DQN has no setting 'learning_rat' \(did you mean learning_rate"):
        check_hyperparameters("dqn", {"learning_rat": 1e-3})
    with pytest.raises(ValueError, match=r"^unknown keyword 'frame_skp' \(did you mean frame_skip\?\) for the "
                                         "vectorized MuJoCo world"):
        gym.make_vec("CraftSuite/Reach-Cont-v0", num_envs=2, vectorization_mode="vector_entry_point", frame_skp=2)


def test_closest_ignores_case_and_keeps_the_known_spelling():
    assert closest("toolhome", ["ToolHome", "Reach"]) == ["ToolHome"]
    assert closest("qqqq", ["ToolHome", "Reach"]) == []
    assert closest("toolhme", ["ToolHome", "toolhome", "Reach"]) == ["ToolHome", "toolhome"]  # neither hides the other


@pytest.mark.parametrize("look_up, start", [
    (lambda: resolve_task("Blindcraftsman"), "unknown task 'Blindcraftsman' (did you mean BlindCraftsman"),
    (lambda: suite_named("standrd"), "unknown suite 'standrd' (did you mean standard?); suites: quick, standard"),
    (lambda: check_methods(["td3-dinamic"]), "unknown method 'td3-dinamic' (did you mean td3-dynamic"),
    (lambda: hyperparameter_examples("sac"), "unknown algorithm 'sac'; algorithms: dqn, td3"),
    (lambda: craftsuite.evaluate(lambda obs: 0, "CraftSuite/Reach-Grid10-v0", suite="hrd"),
     "unknown suite 'hrd' (did you mean hard?)"),
])
def test_each_lookup_says_it_the_one_way(look_up, start):
    with pytest.raises(UnknownName) as caught:
        look_up()
    message = str(caught.value)
    assert message.startswith(start) and "[" not in message and "\n" not in message
