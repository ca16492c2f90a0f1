"""Parameter declarations: a method states its options once; UI, CLI and API all derive from the declaration.

The Blender layer turns each :class:`Param` into a property (float, int, bool, enum, float vector of size 3) and
the CLI's ``--set key=value`` strings go through the same :func:`resolve`, so every entry point accepts and rejects
the same values.
"""
import math
import numbers
import re
from dataclasses import dataclass

TYPES = ("float", "int", "bool", "enum", "vector")
TRUE_WORDS = ("1", "true", "yes", "on")
FALSE_WORDS = ("0", "false", "no", "off")


@dataclass(frozen=True)
class Param:
    """One method parameter.

    Attributes:
        name: a Python identifier, the keyword ``rig(mesh, **params)`` receives.
        type: one of ``TYPES``. A ``vector`` is three floats (e.g. a view direction); min/max bound each component.
        default: the value used when none is given; coerced and range-checked like a user value.
        min, max: inclusive bounds for float, int and vector; None for unbounded.
        items: the allowed strings of an enum (Blender enum identifiers, e.g. ``("AUTO", "X", "Y", "Z")``).
        description: one sentence for tooltips and ``--help``.
        label: shown in the UI; defaults to the name with underscores as spaces, capitalised.
    """

    name: str
    type: str
    default: object
    min: float = None
    max: float = None
    items: tuple = ()
    description: str = ""
    label: str = ""

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"parameter name must be a Python identifier, got {self.name!r}")
        if self.type not in TYPES:
            raise ValueError(f"parameter {self.name!r}: type must be one of {', '.join(TYPES)}, got {self.type!r}")
        self._check_bounds()
        self._check_items()
        if not isinstance(self.description, str) or not isinstance(self.label, str):
            raise ValueError(f"parameter {self.name!r}: description and label must be strings")
        if not self.label:
            object.__setattr__(self, "label", self.name.replace("_", " ").capitalize())
        object.__setattr__(self, "default", self.coerce(self.default))

    def coerce(self, value):
        """``value`` (a Python value or a string from the command line) as this parameter's type, range-checked;
        ValueError saying what was expected otherwise."""
        return getattr(self, f"_coerce_{self.type}")(value)

    def _check_bounds(self):
        if self.type not in ("float", "int", "vector"):
            if self.min is not None or self.max is not None:
                raise ValueError(f"parameter {self.name!r}: min/max apply only to float, int and vector")
            return
        for bound in (self.min, self.max):
            if bound is not None and not (_is_real(bound) and math.isfinite(bound)):
                raise ValueError(f"parameter {self.name!r}: min/max must be finite numbers, got {bound!r}")
        if self.min is not None and self.max is not None and self.min > self.max:
            raise ValueError(f"parameter {self.name!r}: min {self.min} exceeds max {self.max}")

    def _check_items(self):
        if self.type != "enum":
            if self.items:
                raise ValueError(f"parameter {self.name!r}: items apply only to enum")
            return
        items = tuple(self.items) if not isinstance(self.items, str) else ()
        if not items or not all(isinstance(item, str) and item for item in items):
            raise ValueError(f"parameter {self.name!r}: an enum needs items, a sequence of non-empty strings")
        if len({item.lower() for item in items}) != len(items):
            raise ValueError(f"parameter {self.name!r}: enum items must differ ignoring case, got {items}")
        object.__setattr__(self, "items", items)

    def _fail(self, expected, value):
        raise ValueError(f"parameter {self.name!r}: expected {expected}, got {value!r}")

    def _in_range(self, value):
        if self.min is not None and value < self.min:
            raise ValueError(f"parameter {self.name!r}: {value} is below the minimum {self.min}")
        if self.max is not None and value > self.max:
            raise ValueError(f"parameter {self.name!r}: {value} is above the maximum {self.max}")
        return value

    def _real(self, value, expected):
        if isinstance(value, str):
            try:
                value = float(value)
            except ValueError:
                self._fail(expected, value)
        if not _is_real(value) or not math.isfinite(value):
            self._fail(expected, value)
        return float(value)

    def _coerce_float(self, value):
        return self._in_range(self._real(value, "a finite number"))

    def _coerce_int(self, value):
        if isinstance(value, numbers.Integral) and not isinstance(value, bool):
            return self._in_range(int(value))
        number = self._real(value, "an integer")
        if not number.is_integer():
            self._fail("an integer", value)
        return self._in_range(int(number))

    def _coerce_bool(self, value):
        if isinstance(value, str) and value.strip().lower() in TRUE_WORDS + FALSE_WORDS:
            return value.strip().lower() in TRUE_WORDS
        if isinstance(value, numbers.Integral) and value in (0, 1):
            return bool(value)
        self._fail(f"a boolean ({'/'.join(TRUE_WORDS)} or {'/'.join(FALSE_WORDS)})", value)

    def _coerce_enum(self, value):
        if isinstance(value, str):
            matches = [item for item in self.items if item.lower() == value.strip().lower()]
            if matches:
                return matches[0]
        self._fail(f"one of {', '.join(self.items)}", value)

    def _coerce_vector(self, value):
        parts = re.split(r"[\s,]+", value.strip()) if isinstance(value, str) else value
        try:
            parts = list(parts)
        except TypeError:
            parts = None
        if parts is None or len(parts) != 3:
            self._fail("three numbers (e.g. 0,0,1)", value)
        return tuple(self._in_range(self._real(part, "three finite numbers")) for part in parts)


def resolve(declared, given):
    """Every declared parameter's value: ``given[name]`` coerced and range-checked, else the default.

    Unknown names raise ValueError listing the valid ones, so a typo never silently falls back to a default.
    """
    by_name = {param.name: param for param in declared}
    unknown = sorted(set(given) - set(by_name))
    if unknown:
        valid = ", ".join(by_name) or "none"
        raise ValueError(f"unknown parameter{'s' if len(unknown) > 1 else ''} {', '.join(unknown)}; valid: {valid}")
    return {name: param.coerce(given[name]) if name in given else param.default for name, param in by_name.items()}


def _is_real(value):
    return isinstance(value, numbers.Real) and not isinstance(value, bool)
