"""Two rows of this experiment's own (``craftsuite.methods.register_method``): the MuJoCo
shaping baselines with one change, the potential negated (``potential_sign=-1``: Phi = -V,
the sign of Toro Icarte et al.'s code but not its scale or discount, against the package's
Phi = V). On the command line:
``--methods shaping_sign:td3-rs-negated shaping_sign:td3-dynamic-rs-negated``, with this
folder on PYTHONPATH."""

from craftsuite.methods import METHODS, Method, register_method

for _name in ("td3-rs", "td3-dynamic-rs"):
    _row = METHODS[_name]
    register_method(Method(f"{_name}-negated", _row.world, _row.algorithm, _row.product, shaping=_row.shaping,
                           potential_sign=-1, description=f"{_name} with the potential negated (Phi = -V)"))


def main() -> int:
    """Print the rows this module registers, as the command line reads them."""
    for name in ("td3-rs-negated", "td3-dynamic-rs-negated"):
        row = METHODS[name]
        print(f"shaping_sign:{name}: {row.description} (settings {row.settings()})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
