"""The one deprecation path of the package: a form deprecated in the coming release (0.2.0)
keeps working through that release with a FutureWarning -- shown to users, where a
DeprecationWarning is hidden outside ``__main__`` -- that names what to use instead and the
release it goes in.  An array attribute that became a method of the same name is both for
that release (``_MethodWithArrayShim``)."""

from __future__ import annotations

import functools
import inspect
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

REMOVAL_VERSION = "0.3.0"


def deprecated(old: str, new: str, stacklevel: int = 3) -> None:
    """Warn that ``old`` is deprecated and removed in ``REMOVAL_VERSION``, naming ``new``.

    Parameters
    ----------
    old : str
        The deprecated form, as the user wrote it (``"granular.demo"``).
    new : str
        What to write instead, as a sentence (``"use granular.cli.demo"``).
    stacklevel : int
        As for `warnings.warn`: 3 points at the caller of the function that calls this.
    """
    warnings.warn(
        f"{old} is deprecated and removed in granular {REMOVAL_VERSION}; {new}",
        FutureWarning,
        stacklevel=stacklevel,
    )


class _ArrayAndMethod(np.ndarray):
    """The transition from an array attribute to a method of the same name:
    ``result.msd`` used to be the (T,) array and is now the method ``result.msd()``.
    This object is both -- called, it runs the method; used as an array (indexing,
    arithmetic, NumPy functions), it is the old array and warns (FutureWarning) that this
    use goes in granular ``REMOVAL_VERSION``.  Results of array use are plain arrays.
    ``inspect.signature`` gives the method's.  Goes in ``REMOVAL_VERSION`` with the array
    use, leaving plain methods."""

    _method: Any  # the bound method (None only on views made by NumPy itself)
    _name: str

    def __new__(
        cls, values: NDArray[np.float64], method: Callable[..., NDArray[np.float64]], name: str
    ) -> _ArrayAndMethod:
        obj = np.asarray(values).view(cls)
        obj._method, obj._name = method, name
        return obj

    def __array_finalize__(self, obj: object) -> None:
        self._method = getattr(obj, "_method", None)
        self._name = getattr(obj, "_name", "")

    def __call__(self, *args: Any, **kwargs: Any) -> NDArray[np.float64]:
        return self._method(*args, **kwargs)

    @property
    def __signature__(self) -> inspect.Signature:
        return inspect.signature(self._method)

    def _deprecated(self) -> None:
        deprecated(
            f"using result.{self._name} as an array",
            f"call result.{self._name}() (the same numbers)",
            stacklevel=4,
        )

    def __getitem__(self, index: Any) -> Any:
        self._deprecated()
        return self.view(np.ndarray)[index]

    def __array_ufunc__(self, ufunc: np.ufunc, method: str, *inputs: Any, **kwargs: Any) -> Any:
        self._deprecated()
        plain = tuple(x.view(np.ndarray) if isinstance(x, _ArrayAndMethod) else x for x in inputs)
        if "out" in kwargs:
            kwargs["out"] = tuple(
                x.view(np.ndarray) if isinstance(x, _ArrayAndMethod) else x for x in kwargs["out"]
            )
        return getattr(ufunc, method)(*plain, **kwargs)

    def __array_function__(self, func: Any, types: Any, args: Any, kwargs: Any) -> Any:
        self._deprecated()

        def plain(x: Any) -> Any:
            if isinstance(x, _ArrayAndMethod):
                return x.view(np.ndarray)
            if isinstance(x, (list, tuple)):
                return type(x)(plain(y) for y in x)
            return x

        return func(*plain(args), **{k: plain(v) for k, v in kwargs.items()})

    def __repr__(self) -> str:
        return repr(self.view(np.ndarray))

    def __reduce__(self) -> Any:  # pickles as the plain array it holds
        return self.view(np.ndarray).__reduce__()


class _MethodWithArrayShim:
    """A method that, for one more release, is also the array it replaced: on the class it
    is the plain function (so ``inspect.signature(LangevinResult.msd)`` and ``help`` work),
    on a result an ``_ArrayAndMethod`` of the array in ``values`` (an attribute name).
    Goes in ``REMOVAL_VERSION``: the methods then are plain methods."""

    def __init__(self, values: str) -> None:
        self.values = values

    def __call__(self, method: Callable[..., Any]) -> _MethodWithArrayShim:
        self.method = method
        functools.update_wrapper(self, method)
        return self

    def __get__(self, result: Any, owner: type | None = None) -> Any:
        if result is None:
            return self.method
        bound = self.method.__get__(result, owner)
        return _ArrayAndMethod(getattr(result, self.values), bound, self.method.__name__)
