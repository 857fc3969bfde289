"""TD3 exploration noise from specs (data), as run configs and --hyper name it."""

import numpy as np
import pytest
from stable_baselines3.common.noise import NormalActionNoise, OrnsteinUhlenbeckActionNoise

from craftsuite.agents.factory import make_agent
from craftsuite.agents.noise import PersistentActionNoise, make_action_noise

CONT = "CraftSuite/BlindCraftsman-Cont-v0"


def test_persistent_noise_holds_a_draw_for_about_one_over_resample_steps():
    noise = PersistentActionNoise(sigma=0.6, resample=0.1, seed=0)
    draws = np.array([noise() for _ in range(20_000)])
    changes = np.flatnonzero(np.any(draws[1:] != draws[:-1], axis=1))
    assert 8 < np.diff(changes).mean() < 12  # runs of 1 / 0.1 steps
    assert abs(draws[changes + 1].std() - 0.6) < 0.05  # each run is one N(0, 0.6) draw
    held = noise()
    noise.reset()
    assert not np.array_equal(noise.eps, held)  # a new episode starts a new run
    again = PersistentActionNoise(sigma=0.6, resample=0.1, seed=0)
    assert np.array_equal(np.array([again() for _ in range(100)]), draws[:100])  # seeded


@pytest.mark.parametrize("spec, kind", [({"type": "normal", "sigma": 0.3}, NormalActionNoise),
                                        ({"type": "ou", "sigma": 0.2}, OrnsteinUhlenbeckActionNoise),
                                        ({"type": "persistent", "sigma": 0.6, "resample": 0.1},
                                         PersistentActionNoise)])
def test_specs_build_their_noise(spec, kind):
    noise = make_action_noise(spec, dim=2, seed=1)
    assert isinstance(noise, kind) and noise().shape == (2,)


@pytest.mark.parametrize("spec, message", [
    ({"type": "pink", "sigma": 0.3}, "one of"),
    ({"sigma": 0.3}, "one of"),
    ({"type": "persistent", "sigma": 0.6}, r"takes sigma, resample; missing resample: "),
    ({"type": "normal", "sigma": 0.3, "theta": 0.1}, r"takes sigma; unknown theta: "),
    ({"type": "persistent", "sigma": 0.6, "resample": 0}, "resample is a probability"),
    ({"type": "normal", "sigma": float("nan")}, "sigma must be >= 0"),
    ({"type": "normal", "sigma": "big"}, "takes numbers"),
])
def test_bad_specs_name_the_problem(spec, message):
    with pytest.raises(ValueError, match=message):
        make_action_noise(spec, dim=2)


def test_make_agent_takes_a_spec_and_keeps_the_white_default():
    small = dict(buffer_size=1_000, policy_kwargs={"net_arch": [16]})
    assert isinstance(make_agent("td3", CONT, **small).action_noise, NormalActionNoise)
    agent = make_agent("td3", CONT, seed=3, action_noise={"type": "persistent", "sigma": 0.6, "resample": 0.1},
                       **small)
    assert isinstance(agent.action_noise, PersistentActionNoise) and agent.action_noise.resample == 0.1
