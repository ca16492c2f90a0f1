"""Tuning tables: every tuned number of a method in one frozen dataclass, each field with the reason for its value.

A method's table subclasses :class:`TuningTable` (and the tables of the shared pieces it uses, such as
``core.joints.JointTuning``), declaring each number with :func:`tuned`. The user-facing options stay the method's
declared ``Param``s; tuning is for developers, tests and benchmarks: ``table.changed(name=value)`` gives a copy with
one value changed by name, and ``python -m rigger methods --tuning`` prints every table.
"""
import dataclasses
import numbers


def tuned(value, why):
    """A tuning field: its default ``value`` and, in one line, why it is that."""
    return dataclasses.field(default=value, metadata={"why": why})


@dataclasses.dataclass(frozen=True)
class TuningTable:
    """Base of the tuning tables (frozen dataclasses whose fields are all declared with :func:`tuned`)."""

    def changed(self, **values):
        """A copy with the named values changed; ValueError naming the valid fields for an unknown name, and for a
        value of another kind than the default's (any real number for a float, any integer for an int)."""
        fields = {field.name: field for field in dataclasses.fields(self)}
        unknown = sorted(set(values) - set(fields))
        if unknown:
            raise ValueError(f"unknown tuning value{'s' if len(unknown) > 1 else ''} {', '.join(unknown)} of "
                             f"{type(self).__name__}; valid: {', '.join(fields)}")
        typed = {}
        for name, value in values.items():
            default = fields[name].default
            kind = {float: numbers.Real, int: numbers.Integral}.get(type(default), type(default))
            if not isinstance(value, kind) or isinstance(value, bool) != isinstance(default, bool):
                raise ValueError(f"tuning value {name} must be a {type(default).__name__} like its default "
                                 f"{default!r}, got {value!r}")
            typed[name] = type(default)(value)
        return dataclasses.replace(self, **typed)

    @classmethod
    def rows(cls):
        """(name, default, why, the class that declares it) of every field, in declaration order."""
        owners = {}
        for klass in reversed(cls.__mro__):
            for field in getattr(klass, "__dataclass_fields__", {}).values():
                owners.setdefault(field.name, klass)
        return [(field.name, field.default, field.metadata.get("why", ""), owners[field.name])
                for field in dataclasses.fields(cls)]
