"""A batch's per-shot objects given once each: `PerShot`, shot i's object being `objects[index[i]]`.

A sweep's chunk of 65,536 shots mostly shares a few airs, winds and grounds. Given as a PerShot, an engine reads what
it needs of each distinct object once and spreads it over the shots by the index (`column`), without a Python step
a shot: at a GPU's half a microsecond a shot, a step a shot would cost more than the flight.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Generic, TypeVar

import numpy as np
from golfflight.errors import InputError

T = TypeVar("T")


class PerShot(Sequence, Generic[T]):
    """One object a shot, each distinct object held once: shot i's is `objects[index[i]]`. Only objects some shot
    has are kept (an engine reads every one: a replay's reference where no shot asks for one is None)."""

    def __init__(self, objects: Sequence[T], index: np.ndarray) -> None:
        objects, index = list(objects), np.asarray(index, dtype=np.intp)
        used = np.bincount(index, minlength=len(objects)) > 0
        if not used.all():
            index = (np.cumsum(used) - 1)[index]
            objects = [o for o, u in zip(objects, used.tolist(), strict=True) if u]
        self.objects, self.index = objects, index

    @classmethod
    def of(cls, given: PerShot[T] | Sequence[T] | T, n: int, name: str = "objects") -> PerShot[T]:
        """`given` as a PerShot of n shots: as it is, one a shot (another sequence), or one object for every
        shot. InputError naming `name` where a sequence's length is not n."""
        if isinstance(given, PerShot):
            shared = given
        elif isinstance(given, Sequence):
            shared = cls.each(given)
        else:
            return cls._used([given], np.zeros(n, dtype=np.intp)) if n else cls([given], np.zeros(0, dtype=np.intp))
        if len(shared) != n:
            raise InputError(f"{len(shared)} {name} for {n} launches")
        return shared

    @classmethod
    def each(cls, objects: Sequence[T]) -> PerShot[T]:
        """One object a shot, in order (every one used: no search for unused ones, which a single shot would pay)."""
        return cls._used(list(objects), np.arange(len(objects)))

    @classmethod
    def _used(cls, objects: list[T], index: np.ndarray) -> PerShot[T]:
        """A PerShot of objects that `index` uses every one of, as given."""
        shared = cls.__new__(cls)
        shared.objects, shared.index = objects, index
        return shared

    def __len__(self) -> int:
        return len(self.index)

    def __getitem__(self, shot):
        if isinstance(shot, slice):
            return self.take(np.arange(len(self))[shot])
        return self.objects[self.index[shot]]

    def column(self, read: Callable[[T], Any], dtype: Any = float) -> np.ndarray:
        """`read` of every shot's object as an array [N, ...], `read` called once per distinct object."""
        return np.array([read(o) for o in self.objects], dtype=dtype)[self.index]

    def take(self, shots: np.ndarray) -> PerShot[T]:
        """The objects of some shots of the batch, in that order (only the objects they have)."""
        return PerShot(self.objects, self.index[np.asarray(shots, dtype=np.intp)])

    def plus(self, *others: PerShot[T]) -> PerShot[T]:
        """This batch's shots followed by those of `others`."""
        objects, index = list(self.objects), [self.index]
        for other in others:
            index.append(other.index + len(objects))
            objects += other.objects
        return PerShot(objects, np.concatenate(index))
