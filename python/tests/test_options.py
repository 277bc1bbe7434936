"""The method options come from the library's descriptions
(``_feedid.method_options()``): the keywords, the stubs, the docstrings and
the messages say what they say."""

import re
from pathlib import Path

import numpy as np
import pytest

import feedid
from feedid import _feedid

STUBS = Path(feedid.__file__).with_name("_feedid.pyi")
TYPES = {"float": "float", "int": "int", "choice": "str", "orders": "str"}


def test_the_descriptions_keep_the_python_keywords_and_defaults():
    specs = {s["key"]: s for s in _feedid.method_options()}
    assert {s["python"] for s in specs.values()} == {
        "order", "solver", "time_origin", "prediction", "simplex_start", "lambda_", "ridge",
        "hidden", "train_samples", "epochs", "learning_rate", "online_steps", "nn_seed",
    }
    assert specs["lambda"]["python"] == "lambda_" and specs["lambda"]["flag"] == "--lambda"
    assert [m["method"] for m in specs["order"]["methods"]] == ["arx", "rls", "nn", "auto"]
    assert specs["nn_seed"]["flag"] == "--nn-seed" and specs["hidden"]["defaults"] == "16"
    assert specs["lambda"]["defaults"] == "0.999"
    assert specs["solver"]["choices"] == ["qr", "simplex"]
    assert specs["lambda"]["range"]["text"] == "in (0, 1]"
    for s in specs.values():
        assert s["help"].endswith(f"[default: {s['defaults']}]"), s
    names = [m["name"] for m in _feedid.methods()]
    assert names == ["auto", "paper", "arx", "rls", "oe", "nn"]
    windows = {m["name"]: m["default_window"] for m in _feedid.methods()}
    assert windows == {"auto": 50, "paper": 20, "arx": 100, "rls": 100, "oe": 200, "nn": 100}


def test_the_stubs_have_every_option_with_its_type_and_default():
    text = STUBS.read_text(encoding="utf-8")
    for s in _feedid.method_options():
        line = f"{s['python']}: Optional[{TYPES[s['kind']]}] = None,"
        assert text.count(line) == 2, line  # Streamer and identify


def test_the_docstrings_name_every_option_with_its_help():
    for doc in (feedid.identify.__doc__, feedid.Streamer.__doc__):
        assert "{method_" not in doc
        for m in _feedid.methods():
            assert f"``{m['name']}``" in doc and f"{m['name']} {m['default_window']}" in doc
        flat = re.sub(r"\s+", " ", doc)
        for s in _feedid.method_options():
            assert re.search(rf"\b{s['key']}\b", flat), s["key"]
            if s["key"] != "order":  # a parameter of its own
                assert s["help"] in flat, s["help"]


def test_options_are_checked_by_the_library_and_refused_where_they_do_not_apply():
    t = np.arange(300) * 2e-4
    u = np.minimum(t, 0.03)
    y = np.concatenate([[0.0, 0.0], u[:-2]])
    runs = [
        feedid.identify(t, u, y, method="rls", window=40, **kw).predicted
        for kw in ({"lambda": 0.9}, {"lambda_": 0.9}, {})
    ]
    np.testing.assert_array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0], runs[2], equal_nan=True)
    with pytest.raises(feedid.InputError, match=r"invalid lambda `2`: expected a number in \(0, 1\]"):
        feedid.identify(t, u, u, method="rls", **{"lambda": 2.0})
    with pytest.raises(feedid.InputError, match=r"ridge does not apply to method rls \(only to arx, auto\)"):
        feedid.Streamer(method="rls", ridge=0.0)
    with pytest.raises(
        feedid.InputError, match=r'simplex_start does not apply to method arx \(only to paper \(with solver="simplex"\)\)'
    ):
        feedid.identify(t, u, u, method="arx", simplex_start="previous")
    with pytest.raises(TypeError, match="unknown option 'lamda'.*lambda \\(rls\\)"):
        feedid.Streamer(method="rls", lamda=0.9)
    with pytest.raises(TypeError, match="lambda_"):
        _feedid.Streamer(method="rls", lambda_="x")
    with pytest.raises(TypeError, match="unexpected keyword argument 'nope'"):
        _feedid.Streamer(nope=1)
