"""A row of this experiment's own (``craftsuite.methods.register_method``): the MuJoCo
``td3-static`` student with one change, the distilled target left off the automaton's
self-loops (``self_loops=False``; its fade, rho 0.999, as the row's). On the command line:
``--methods td3_loops_off:td3-static-loops-off``, with this folder on PYTHONPATH."""

from craftsuite.methods import METHODS, Method, register_method

_row = METHODS["td3-static"]
register_method(Method("td3-static-loops-off", _row.world, _row.algorithm, _row.product, _row.distill,
                       target={"self_loops": False},
                       description="td3-static with the distilled target off the automaton's self-loops"))


def main() -> int:
    """Print the row this module registers, as the command line reads it."""
    row = METHODS["td3-static-loops-off"]
    print(f"td3_loops_off:td3-static-loops-off: {row.description} (target {dict(row.target)})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
