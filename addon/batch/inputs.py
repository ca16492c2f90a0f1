"""What a batch rigs: the model files its INPUTS name, found lazily, and the name of each one's results.

An input is a folder (searched recursively; hidden files and folders, and the output folder when it lies inside,
are skipped), a model file, a text file listing model files one per line (relative paths are relative to the list's
folder; blank lines and lines starting with # are ignored), or a glob pattern (``**`` matches any depth). Results
mirror each file's path below its input's folder (the list's folder, the glob's fixed leading folders); a listed
file outside that folder gets its whole path below the output folder. Each file's result names depend on the file,
its folder and the input that named it (and, where two files would share a name, on which came first), so a resumed
run with the same inputs finds them again.
"""
import collections
import dataclasses
import functools
import glob
import os
import pathlib

from . import BatchError

GLOB_CHARACTERS = "*?["
SUMMARY_STEM = "summary"  # the batch's summary.json lies at the top of the output folder
LISTINGS_KEPT = 16  # folders whose model file stems are remembered while the inputs are walked


@dataclasses.dataclass(frozen=True)
class Source:
    """One model file to rig: ``path`` (absolute); ``name``, the summary's name for it (its path below its input's
    folder); ``stem``, its results' path below the output folder without a suffix; ``problem``, why it cannot be
    rigged (a listed file that is missing or is no model file, or whose results another file's would overwrite),
    else None."""

    path: pathlib.Path
    name: str
    stem: pathlib.PurePath
    problem: str | None = None


def sources(inputs, output, fmt, suffixes):
    """A Source for each model file (suffix in ``suffixes``) that the ``inputs`` name, lazily and each file once,
    with results ``<stem>.<fmt>`` and ``<stem>.json`` in folder ``output``. The stem is the file's path below its
    input's folder without its suffix, or ``<name>_<suffix>`` where that would take another file's results: another
    model file of that stem in its folder, the summary, or (results written beside the inputs) the file itself.
    BatchError for an input that is none of the forms, or a folder or list that cannot be read."""
    output = _absolute(output)
    stems = functools.lru_cache(LISTINGS_KEPT)(functools.partial(_model_stems, suffixes=suffixes))
    claimed = {}  # results' stem -> (the file that has it, its name): strings only, for lists of 10^5 files
    for text in inputs:
        for path, root, listed in _expand(text, output, suffixes):
            source = _source(path, root, listed, output, fmt, suffixes, stems)
            key, file = os.path.normcase(str(source.stem)), os.path.normcase(str(path))
            if key not in claimed:
                claimed[key] = file, source.name
                yield source
            elif claimed[key][0] != file:  # another file; the same one named again is rigged once
                yield dataclasses.replace(source, problem=f"its results would overwrite those of {claimed[key][1]}")


def _expand(text, output, suffixes):
    """(absolute path, its input's folder, whether it was named explicitly) for each file input ``text`` names."""
    path = pathlib.Path(text)
    if path.is_dir():
        root = _absolute(path)
        yield from ((file, root, False) for file in _walk(root, output, suffixes))
    elif path.is_file() and path.suffix.lower() in suffixes:
        yield _absolute(path), _absolute(path.parent), True
    elif path.is_file():
        yield from _listed(path, suffixes)
    elif any(character in text for character in GLOB_CHARACTERS):
        root = _absolute(_fixed_folders(path))
        for match in glob.iglob(text, recursive=True):
            match = _absolute(match)
            if match.suffix.lower() in suffixes and match.is_file() and not _below(match, output, root):
                yield match, root, False
    else:
        raise BatchError(f"{text}: no such file or folder")


def _walk(folder, output, suffixes):
    """The model files below ``folder`` in name order, depth first, leaving out hidden entries, ``output`` and
    folders reached through symbolic links (which could loop)."""
    try:
        entries = sorted(os.scandir(folder), key=lambda entry: entry.name)
    except OSError as error:
        raise BatchError(f"{folder}: {error.strerror or error}") from None
    for entry in entries:
        path = pathlib.Path(entry.path)
        if entry.name.startswith("."):
            continue
        if entry.is_dir(follow_symlinks=False):
            if path != output:
                yield from _walk(path, output, suffixes)
        elif path.suffix.lower() in suffixes and entry.is_file():
            yield path


def _listed(list_file, suffixes):
    folder = _absolute(list_file.parent)
    try:
        with open(list_file, encoding="utf-8") as lines:
            for line in lines:
                entry = line.strip()
                if entry and not entry.startswith("#"):
                    yield _absolute(folder / entry), folder, True
    except UnicodeDecodeError:
        raise BatchError(f"{list_file}: neither a model file ({', '.join(suffixes)}) nor a text file listing "
                         f"model files") from None
    except OSError as error:
        raise BatchError(f"{list_file}: {error.strerror or error}") from None


def _fixed_folders(pattern):
    """The leading folders of glob ``pattern`` that hold no wildcard: its matches' common folder."""
    fixed = []
    for part in pattern.parts[:-1]:
        if any(character in part for character in GLOB_CHARACTERS):
            break
        fixed.append(part)
    return pathlib.Path(*fixed) if fixed else pathlib.Path(".")


def _below(path, output, root):
    """Whether ``path`` lies in ``output`` where that is a folder inside ``root`` (results are not inputs)."""
    return output != root and output.is_relative_to(root) and path.is_relative_to(output)


def _source(path, root, listed, output, fmt, suffixes, stems):
    try:
        relative = path.relative_to(root)
        name = relative.as_posix()
    except ValueError:  # a listed file outside the list's folder
        relative, name = pathlib.Path(*path.parts[1:]), str(path)
    problem = None
    if listed and path.suffix.lower() not in suffixes:
        problem = f"{path}: cannot read {path.suffix or 'files without a suffix'}; use {', '.join(suffixes)}"
    elif listed and not path.is_file():
        problem = f"{path}: no such file"
    clashes = (stems(path.parent)[path.stem] > 1
               or relative.parent == pathlib.Path(".") and path.stem == SUMMARY_STEM
               or output / relative.parent / f"{path.stem}.{fmt}" == path)
    stem = relative.with_name(f"{path.stem}_{path.suffix[1:]}" if clashes else path.stem)
    return Source(path, name, stem, problem)


def _model_stems(folder, suffixes):
    """How many model files of ``folder`` have each stem."""
    try:
        return collections.Counter(pathlib.Path(entry.name).stem for entry in os.scandir(folder)
                                   if pathlib.Path(entry.name).suffix.lower() in suffixes and entry.is_file())
    except OSError:
        return collections.Counter()


def _absolute(path):
    """``path`` absolute and normalised (``..`` folded), symbolic links kept as named."""
    return pathlib.Path(os.path.abspath(path))
