"""Two rows of this experiment's own (``craftsuite.methods.register_method``): the grid's
``static`` and ``dynamic`` students with one change, the distilled target left off the
automaton's self-loops (``self_loops=False``; its fade, rho 0.999, as theirs). On the command
line: ``--methods loops_off:static-loops-off loops_off:dynamic-loops-off``, with this folder
on PYTHONPATH."""

from craftsuite.methods import METHODS, Method, register_method

for _name in ("static", "dynamic"):
    _row = METHODS[_name]
    register_method(Method(f"{_name}-loops-off", _row.world, _row.algorithm, _row.product, _row.distill,
                           target={"self_loops": False},
                           description=f"{_name} with the distilled target off the automaton's self-loops"))


def main() -> int:
    """Print the rows this module registers, as the command line reads them."""
    for name in ("static-loops-off", "dynamic-loops-off"):
        row = METHODS[name]
        print(f"loops_off:{name}: {row.description} (target {dict(row.target)})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
