"""Every public class, method and function of the Python module has a docstring, and help(uwbtdoa) lists the
classes (the module docstring names each with one line)."""
import inspect
import pydoc
import re

import uwbtdoa as u
from uwbtdoa import plots


def _own_text(obj, name: str) -> str:
    """The docstring without the signature lines pybind11 puts first (those are there even without a docstring)."""
    doc = inspect.getdoc(obj) or ""
    lines = [line for line in doc.splitlines()
             if not re.match(rf"^(\d+\. )?{re.escape(name)}\(", line) and line.strip() != "Overloaded function."]
    return "\n".join(lines).strip()


def _public():
    for name in u.__all__:
        obj = getattr(u, name)
        if inspect.isclass(obj):
            yield name, name, obj
            for attr, member in vars(obj).items():
                if attr.startswith("_") and attr != "__init__":
                    continue
                yield f"{name}.{attr}", attr, member
        elif callable(obj):
            yield name, name, obj
    for name, obj in vars(plots).items():
        if not name.startswith("_") and (inspect.isfunction(obj) or inspect.isclass(obj)) \
                and obj.__module__ == plots.__name__:
            yield f"plots.{name}", name, obj


def test_every_public_class_and_function_has_a_docstring():
    names = [full for full, _, _ in _public()]
    assert "Estimator" in names and "Estimator.add_tdoa" in names and "localize_flight" in names
    missing = [full for full, short, obj in _public() if not _own_text(obj, short)]
    assert not missing, f"no docstring: {missing}"


def test_help_lists_every_class_with_one_line():
    text = pydoc.render_doc(u, renderer=pydoc.plaintext)
    classes = [n for n in u.__all__ if inspect.isclass(getattr(u, n))]
    assert "Estimator" in classes and "Flight" in classes
    summary = u.__doc__
    for name in classes:
        assert re.search(rf"^    {name}\s+\S", summary, re.M), f"{name} has no line in the module docstring"
        assert re.search(rf"^\s+class {name}\b", text, re.M), f"help(uwbtdoa) does not list {name}"
