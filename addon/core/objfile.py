"""What Blender's OBJ importer reads silently wrong: a vertex coordinate that is no finite number ("nan", "inf", an
exponent past the range of Blender's 32-bit floats, a word) becomes 0, a spike to the origin that rigs and skins
without a warning; and a face it cannot read is dropped, which the file's count of faces shows."""
import math
import pathlib
import re

CHUNK_BYTES = 1 << 24  # read this much at a time (and on to the end of its line): a large file is never held whole
_WORDS = (b"nan", b"inf")  # in lowered text, with a large exponent: what could spell a non-finite number
_EXPONENT = re.compile(rb"e\+?0*(?:3[89]|[4-9]\d|[1-9]\d\d)")  # may pass FLOAT_MAX (a literal first: fast)
_WORD = re.compile(rb"^v[ \t][-+0-9.e \t\r]*+[^-+0-9.e \t\r\n]", re.MULTILINE)  # a v line with more than numbers
FLOAT_MAX = 3.4028234663852886e38  # Blender's coordinates are 32-bit floats: beyond this the importer reads 0


class ObjError(ValueError):
    """An OBJ file that Blender would read wrong, or not at all; the message names the file and the line."""


def check(path):
    """The number of faces (``f`` lines) of the OBJ file at ``path`` (Blender's importer drops the faces that name a
    vertex the file lacks, or one twice: fewer faces imported than this is a loss to report); ObjError naming the
    first ``v`` line whose coordinates are not all numbers within ``FLOAT_MAX``. Only lines holding "nan", "inf", an
    exponent of 38 or more or a character no number has are parsed, so a sound file costs a pass of a byte search and
    one of a regular expression."""
    path = pathlib.Path(path)
    faces = 0
    try:
        with open(path, "rb") as file:
            lines_before = 0
            while chunk := file.read(CHUNK_BYTES):
                chunk += file.readline()  # whole lines only
                _check_chunk(path, chunk, lines_before)
                lines_before += chunk.count(b"\n")
                faces += chunk.count(b"\nf ") + chunk.count(b"\nf\t") + chunk.startswith((b"f ", b"f\t"))
    except OSError as error:
        raise ObjError(f"{path}: cannot read it: {error.strerror or error}") from None
    return faces


def _suspects(lowered):
    """Where "nan", "inf", an exponent of 38 or more or a ``v`` line with a character no number has occur in
    ``lowered`` text."""
    for word in _WORDS:
        at = lowered.find(word)
        while at >= 0:
            yield at
            at = lowered.find(word, at + 1)
    yield from (match.start() for match in _EXPONENT.finditer(lowered))
    yield from (match.start() for match in _WORD.finditer(lowered))


def _check_chunk(path, chunk, lines_before):
    lowered = chunk.lower()
    for start in sorted({lowered.rfind(b"\n", 0, at) + 1 for at in _suspects(lowered)}):
        end = lowered.find(b"\n", start)
        words = chunk[start:len(chunk) if end < 0 else end].split()
        if words[:1] != [b"v"]:
            continue
        for word in words[1:4]:
            try:
                finite = math.isfinite(float(word)) and abs(float(word)) <= FLOAT_MAX
            except ValueError:
                finite = False
            if not finite:
                line = lines_before + chunk.count(b"\n", 0, start) + 1
                raise ObjError(f"{path}: line {line}: vertex coordinate {word.decode(errors='replace')!r} is not a "
                               f"finite number Blender can hold (its importer would read it as 0)")
