"""Read-only views of the library's report structs (ssFrameReport, ssApplyReport, ssStepInfo ...), fields read lazily.

A view holds the C struct the library filled and reads a field only when it is asked for, so that a frame costs one
small allocation and no copy (Stepper.step makes one report a frame; building a dataclass of every field cost
more than the frame of a small world). The fields are the C struct's own, read from the cffi declarations: a field
added in C appears here with the next build, nested structs as nested views. Each view owns its own C memory,
so a report kept from an earlier frame keeps its values.

    class FrameReport(StructView, c_type="ssFrameReport", convert={"failed_body": address_of}): ...
    FrameReport.of(filled)                  # the struct the library filled, read in place
    FrameReport(steps=1, step_s=1 / 60)     # one made by hand (fields not given are 0), e.g. to compare
"""

from __future__ import annotations

import operator

from steadystep.core._native import ffi

_VIEWS: dict[str, type] = {}  # C struct name -> its view class (declared or made for a nested struct)


def address_of(pointer) -> int:
    """A C pointer field (an ODE handle) as its integer address, 0 for NULL."""
    return int(ffi.cast("uintptr_t", pointer))


class StructView:
    """The fields of one C struct as read-only attributes; FIELDS names them in the C order. Equal to another view of
    the same type with the same values; as_dict() gives plain data (nested views as dicts)."""

    __slots__ = ("_c", "_owner")
    C_TYPE = ""
    FIELDS: tuple[str, ...] = ()

    def __init_subclass__(cls, c_type: str = "", convert: dict | None = None, docs: dict | None = None, **kwargs):
        super().__init_subclass__(**kwargs)
        if not c_type:
            return
        cls.C_TYPE = c_type
        fields = ffi.typeof(c_type).fields
        cls.FIELDS = tuple(name for name, _ in fields)
        for name, field in fields:
            made = _field_property(name, field.type, (convert or {}).get(name))
            # help(view) shows each field's meaning and unit (docs: as the header says it), not the getter's own
            # docstring; a field the C struct gained and docs do not name still says where it is documented.
            doc = (docs or {}).get(name, f"see {c_type} in the library's headers")
            kind = "read-only" if name in (convert or {}) else f"{field.type.cname}, read-only"
            setattr(cls, name, property(made.fget, doc=f"{name} ({kind}): {doc}"))
        _VIEWS[ffi.typeof(c_type).cname] = cls

    def __init__(self, *values, **named):
        """A view of a new struct holding values, in the C order or by field name (nested structs as views or
        dicts; fields not given are 0), e.g. to compare a report with the one expected."""
        if len(values) > len(self.FIELDS):
            raise TypeError(f"{type(self).__name__}: {len(values)} values for {len(self.FIELDS)} fields")
        given = dict(zip(self.FIELDS, values))
        twice = given.keys() & named.keys()
        if twice:
            raise TypeError(f"{type(self).__name__}: {sorted(twice)[0]!r} given twice")
        cdata = self.new()
        _fill(cdata[0], {**given, **named}, type(self).__name__)
        self._c = cdata
        self._owner = None

    @classmethod
    def of(cls, cdata, owner=None):
        """A view of the struct the library filled (cdata: the struct or a pointer to it), read in place; owner keeps
        its memory alive when cdata does not (a nested struct, read from its parent)."""
        view = cls.__new__(cls)
        view._c = cdata
        view._owner = owner
        return view

    @classmethod
    def new(cls):
        """A zeroed C struct of this type (a pointer that owns it), for the library to fill."""
        return ffi.new(f"{cls.C_TYPE}*")

    def as_dict(self) -> dict:
        """The fields as plain data by name, in the C order (nested views as dicts)."""
        return {name: _plain(getattr(self, name)) for name in self.FIELDS}

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self.as_dict() == other.as_dict()

    __hash__ = None

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(f'{name}={getattr(self, name)!r}' for name in self.FIELDS)})"

    def __reduce__(self):
        return _from_dict, (type(self), self.as_dict())


def _plain(value):
    return value.as_dict() if isinstance(value, StructView) else value


def _from_dict(cls, values: dict):
    """A view of a new C struct holding values (unpickling)."""
    return cls(**values)


def _fill(cdata, values: dict, what: str) -> None:
    """Stores values by field name into cdata, as C takes them (a view or a dict for a nested struct, an address
    for a pointer); TypeError naming a field the struct does not have."""
    fields = dict(ffi.typeof(cdata).fields)
    for name, value in values.items():
        if name not in fields:
            raise TypeError(f"{what}: no field {name!r} (fields: {', '.join(fields)})")
        kind = fields[name].type
        if kind.kind == "struct":
            _fill(getattr(cdata, name), value.as_dict() if isinstance(value, StructView) else value, f"{what}.{name}")
        elif kind.kind == "pointer":
            setattr(cdata, name, ffi.cast(kind, value))
        else:
            setattr(cdata, name, value)


def _field_property(name: str, ctype, convert):
    if ctype.kind == "struct":
        def nested(self, view=_view_class(ctype.cname)):
            # A struct field is read in place: the nested view keeps the outer struct's memory alive.
            return view.of(getattr(self._c, name), self._owner if self._owner is not None else self._c)
        return property(nested)
    if convert is not None:
        return property(lambda self: convert(getattr(self._c, name)))
    return property(operator.attrgetter(f"_c.{name}"))  # one C-level lookup, the common case


def _view_class(c_type: str) -> type:
    """The view class of a nested struct: the one declared for it, else one made from its C name."""
    if c_type not in _VIEWS:
        name = c_type.removeprefix("struct ").removeprefix("ss")
        type(name, (StructView,), {"__slots__": (), "__module__": __name__}, c_type=c_type)
    return _VIEWS[c_type]
