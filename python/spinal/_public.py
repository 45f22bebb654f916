"""The public submodules (``curves``, ``fields``, ``ph``, ``quaternions``) re-export their
names from private modules that hold the code; :func:`publish` shows those names under the
public module, where the documentation lists them and pickles find them."""

from typing import Any


def publish(namespace: dict[str, Any]) -> None:
    """Set ``__module__`` of the classes and functions named in ``namespace["__all__"]``
    that come from the private twin ``spinal._<name>`` to the public module's name."""
    public = namespace["__name__"]
    package, _, name = public.rpartition(".")
    private = f"{package}._{name}"
    for attr in namespace["__all__"]:
        obj = namespace[attr]
        if getattr(obj, "__module__", None) == private:
            obj.__module__ = public
