"""The environments' constructor keywords follow the Rust core's `EnvSpec`: every field is
a keyword of `PickEnv`, `PickVecEnv`, the stub and the Gymnasium wrappers, with the core's
default (`ENV_DEFAULTS`, serialised from `EnvSpec::default()`), so a keyword added to the
core and missed in one of them fails here."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path
from typing import Any

import forkbench
import forkbench.gym as fgym
from forkbench import _forkbench

STUB = Path(forkbench.__file__).with_name("_forkbench.pyi")

# Keywords a constructor leaves out, or defaults it sets on purpose, and why.
OWN = {
    ("PickVecEnv", "render_size"): "a vector environment draws no frames",
    ("PalletPickVectorEnv", "render_size"): "a vector environment draws no frames",
    ("PalletPickEnv", "render_size"): "the wrapper draws 320 x 320 frames by default",
}


def plain(v: Any) -> Any:
    """Tuples as lists, as the core's JSON gives them."""
    return [plain(x) for x in v] if isinstance(v, (tuple, list)) else v


def stub_keywords(cls: str) -> dict[str, Any]:
    tree = ast.parse(STUB.read_text())
    node = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls)
    init = next(f for f in node.body if isinstance(f, ast.FunctionDef) and f.name == "__init__")
    return {
        a.arg: ast.literal_eval(d) if d is not None else inspect.Parameter.empty
        for a, d in zip(init.args.kwonlyargs, init.args.kw_defaults)
    }


def signature_keywords(obj: Any) -> dict[str, Any]:
    params = inspect.signature(obj).parameters.values()
    return {p.name: p.default for p in params if p.kind is p.KEYWORD_ONLY}


def check(where: str, got: dict[str, Any]) -> None:
    for name, default in _forkbench.ENV_DEFAULTS.items():
        if (where, name) in OWN:
            continue
        assert name in got, f"{where} lacks the keyword {name!r} of the core's EnvSpec"
        if got[name] is not Ellipsis:  # pyo3 shows a tuple default as ...
            assert plain(got[name]) == default, f"{where}: {name}={got[name]!r}, core {default!r}"


def test_the_core_lists_its_keywords() -> None:
    defaults = _forkbench.ENV_DEFAULTS
    assert {"case", "ticks_per_step", "reward", "episode", "phase_reward"} <= set(defaults)
    assert defaults["ticks_per_step"] == 1 and defaults["episode"] == "pick"
    assert "overrides" not in defaults  # the run's options come as **options


def test_the_bound_constructors_follow_the_core() -> None:
    check("PickEnv", signature_keywords(_forkbench.PickEnv))
    check("PickVecEnv", signature_keywords(_forkbench.PickVecEnv))


def test_the_stub_follows_the_core() -> None:
    check("PickEnv", stub_keywords("PickEnv"))
    check("PickVecEnv", stub_keywords("PickVecEnv"))


def test_the_gymnasium_wrappers_follow_the_core() -> None:
    check("PalletPickEnv", signature_keywords(fgym.PalletPickEnv.__init__))
    check("PalletPickVectorEnv", signature_keywords(fgym.PalletPickVectorEnv.__init__))


def test_a_missing_keyword_is_caught() -> None:
    try:
        check("PickEnv", {k: v for k, v in stub_keywords("PickEnv").items() if k != "path_points"})
    except AssertionError as e:
        assert "path_points" in str(e)
    else:
        raise AssertionError("a constructor without path_points passed")
