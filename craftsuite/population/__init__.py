"""The population engine: every seed of a suite cell trained in one process.

K members' networks are stacked on a leading axis and updated together (``nets``,
``td3``, ``dqn``), their replay preallocated with a sum tree per member (``replay``), their
envs one vector env (``envs``); ``engine.Population`` collects and learns as the SB3
agents do, ``train.train_population`` makes each member an ordinary run directory. The SB3
agents (``craftsuite.agents``) stay the reference and the per-agent API.
"""

from .engine import EngineError, Population, check_supported  # noqa: F401
from .train import train_population  # noqa: F401
