"""The population engine: every seed of a suite cell trained in one process.

K members' networks are stacked on a leading axis and updated together (``nets``,
``td3``, ``dqn``), their replay preallocated with a sum tree per member (``replay``), their
envs one vector env (``envs``); ``engine.Population`` collects and learns,
``train.train_population`` makes each member an ordinary run directory. Every learning rule
CraftSuite trains with lives here once; a member is saved as an SB3 agent
(``craftsuite.agents``), which loads and acts but does not learn.
"""

from .engine import Diverged, EngineError, Population, check_supported  # noqa: F401
from .train import train_population  # noqa: F401
