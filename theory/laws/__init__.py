r"""Contact laws shared by the three models: one file per law, a registry line each.

:mod:`theory.laws.base` holds :class:`ContactLaw` (the compiled pieces the discrete
kernels fuse, their NumPy twins, the static overlap and the long-wave coefficients of a
chain with the law, :class:`LongWave`) and :func:`compile_piece`; each law has its own
file with its compiled and NumPy pieces side by side:

:class:`PowerLaw` (``"power"``, :mod:`theory.laws.power`)
    :math:`F = k[\delta]_+^{n}`: n = 3/2 is Hertz's law for spheres (paper Eq. 1;
    :data:`HERTZ`, the default), n = 1 a linear spring, n = 2 cones; Nesterenko (2001),
    *Dynamics of Heterogeneous Materials*, §1.1.
:class:`ViscoelasticHertz` (``"viscoelastic_hertz"``, :mod:`theory.laws.viscoelastic`)
    :math:`F = \max(0,\ k[\delta^{3/2} + A\delta^{1/2}\dot\delta])`: Kuwabara & Kono
    (1987), Brilliantov et al. (1996); from a measured coefficient of restitution with
    :meth:`ViscoelasticHertz.from_restitution`.

A new law is a new file and one :func:`register_law` call (or one line in :data:`LAWS`):
files and scenarios find it by its ``name`` (:func:`law_from_dict`), and its
:attr:`~ContactLaw.parameters` (:class:`LawParameter`: name, unit, range, default, help)
become keys of a scenario's ``[chain]`` table with their validation and their line in
the scenario reference (:mod:`hertzchain.scenario`); :meth:`ContactLaw.from_params`
builds it from them.
"""

from __future__ import annotations

from typing import Any

from .base import N_PARAMS, ContactLaw, LawParameter, LongWave, compile_piece
from .power import HERTZ, PowerLaw
from .viscoelastic import ViscoelasticHertz

__all__ = ["ContactLaw", "LawParameter", "LongWave", "PowerLaw", "ViscoelasticHertz", "HERTZ",
           "LAWS", "N_PARAMS", "as_law", "compile_piece", "law_from_dict", "register_law"]

LAWS: dict[str, type[ContactLaw]] = {
    PowerLaw.name: PowerLaw,
    ViscoelasticHertz.name: ViscoelasticHertz,
}
"""The registered laws by name (:func:`law_from_dict`)."""


def register_law(cls: type[ContactLaw]) -> type[ContactLaw]:
    """Register a law class under its ``name`` (usable as a class decorator).

    ValueError if ``cls`` is not a :class:`ContactLaw` subclass with a non-empty
    ``name`` and a tuple of :class:`LawParameter` of distinct names as ``parameters``,
    or if another class is registered under that name.
    """
    if not (isinstance(cls, type) and issubclass(cls, ContactLaw)):
        raise ValueError(f"a contact law must subclass theory.laws.ContactLaw (got {cls!r})")
    if not isinstance(cls.name, str) or not cls.name:
        raise ValueError(f"{cls.__name__}.name must be a non-empty string (got {cls.name!r})")
    params = cls.parameters
    if not (isinstance(params, tuple) and all(isinstance(p, LawParameter) for p in params)):
        raise ValueError(f"{cls.__name__}.parameters must be a tuple of "
                         f"theory.laws.LawParameter (got {params!r})")
    names = [p.name for p in params]
    if len(set(names)) != len(names) or "law" in names:
        raise ValueError(f"{cls.__name__}.parameters: names must be distinct and not 'law' "
                         f"(got {names})")
    if LAWS.get(cls.name, cls) is not cls:
        raise ValueError(f"contact law name {cls.name!r} is taken by "
                         f"{LAWS[cls.name].__qualname__}")
    LAWS[cls.name] = cls
    return cls


def law_from_dict(d: dict[str, Any]) -> ContactLaw:
    """The law described by ``d`` (:meth:`ContactLaw.to_dict`); ValueError if unknown."""
    if not isinstance(d, dict) or "law" not in d:
        raise ValueError(f"a contact law description needs a 'law' key (got {d!r})")
    d = dict(d)
    name = d.pop("law")
    if name not in LAWS:
        raise ValueError(f"unknown contact law {name!r}; choose one of {sorted(LAWS)}")
    return LAWS[name](**d)


def as_law(law: ContactLaw | dict | None) -> ContactLaw:
    """``law`` as a :class:`ContactLaw` (None: :data:`HERTZ`; a dict: :func:`law_from_dict`)."""
    if law is None:
        return HERTZ
    if isinstance(law, ContactLaw):
        return law
    if isinstance(law, dict):
        return law_from_dict(law)
    raise ValueError(f"law must be a ContactLaw, a dict or None (got {type(law).__name__})")
