"""Reading HDF5 files that may be hostile: every object reached through hard links only,
every dataset checked (stored in the file itself, of the expected type and shape, of a
declared size within :data:`MAX_DATASET_BYTES`) before any of it is read, and then only the
entries asked for. Used by :mod:`impactqp.io.fclib`; errors are
:class:`~impactqp.errors.ProblemFileError` naming the file and the dataset.

HDF5 lets a file reach into others: external links (an object in another file), soft links
(another name, which may lead to an external link), external raw storage (a dataset whose
bytes are read from other files) and virtual datasets (views of datasets in other files).
Any of them can name a FIFO, where opening waits forever, or a device such as /dev/zero;
all are refused by name, before what they point at is opened.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import OptionalDependencyError, ProblemFileError

MAX_DATASET_BYTES = 2**30
"""Largest dataset (declared shape × item size, and largest chunk) read from an HDF5 file:
1 GiB, some 10⁸ numbers, far above the largest problems of the FCLib collections. A
compressed dataset may declare far more than its file's size; it is refused before reading."""


FCLIB_EXTRA = "fclib"
"""The extra of impactqp's install that brings h5py (``pip install 'impactqp[fclib]'``)."""


def h5py_module() -> Any:
    """h5py, or an error naming the extra that installs it: FCLib's HDF5 files need it,
    Siconos' text files (:mod:`impactqp.io.siconos_text`) do not."""
    try:
        import h5py
    except ImportError:
        raise OptionalDependencyError(
            f"FCLib files (HDF5) need h5py: pip install 'impactqp[{FCLIB_EXTRA}]' (Siconos' "
            "text files, .dat and .dat.gz, are read without it)") from None
    return h5py


class CheckedReader:
    """Datasets of one open HDF5 file, each checked and named in every error.

    Objects are reached through hard links only, and a dataset is read only once its storage
    (in this file: not external, not virtual), type, shape and declared size have been checked,
    and then only the entries asked for."""

    def __init__(self, path: Path, handle: Any) -> None:
        self.path = path
        self.handle = handle

    def error(self, name: str, what: str) -> ProblemFileError:
        return ProblemFileError(f"{self.path}: /{name}: {what}")

    def node(self, name: str) -> Any | None:
        """The object at ``name``, found link by link without following any link that is not
        a hard one (an external link opens another file, a soft one may lead to one); None
        when a link on the way is absent."""
        h5l = h5py_module().h5l
        node = self.handle
        parts = name.split("/")
        for k, part in enumerate(parts):
            where = "/".join(parts[:k + 1])
            if not hasattr(node, "keys"):
                raise self.error("/".join(parts[:k]), "is a dataset, expected a group")
            key = part.encode()
            if not node.id.links.exists(key):
                return None
            kind = node.id.links.get_info(key).type
            if kind == h5l.TYPE_EXTERNAL:
                target, inside = (x.decode(errors="replace") for x in node.id.links.get_val(key))
                raise self.error(where, f"is an external link (to {inside} in {target}); "
                                        "links to other files are refused")
            if kind != h5l.TYPE_HARD:
                what = "a soft link" if kind == h5l.TYPE_SOFT else "a user-defined link"
                raise self.error(where, f"is {what}; only groups and datasets stored under "
                                        "their own name are read")
            node = node[part]
        return node

    def contains(self, name: str) -> bool:
        return self.node(name) is not None

    def stored(self, name: str) -> Any:
        """The dataset at ``name``, its data stored in this file (not in external raw files,
        not a virtual view of other datasets), checked before any of it is read."""
        h5d = h5py_module().h5d
        obj = self.node(name)
        if obj is None:
            raise self.error(name, "missing (an FCLib file needs it)")
        if not hasattr(obj, "dtype") or not hasattr(obj, "chunks"):
            raise self.error(name, "is a group, expected a dataset")
        plist = obj.id.get_create_plist()
        if plist.get_layout() == h5d.VIRTUAL:
            sources = {plist.get_virtual_filename(i) for i in range(plist.get_virtual_count())}
            raise self.error(name, f"is a virtual dataset (a view of datasets in "
                                   f"{', '.join(sorted(sources))}); refused, an FCLib file is "
                                   "read alone")
        if plist.get_external_count():
            target = plist.get_external(0)[0].decode(errors="replace")
            raise self.error(name, f"is stored in external raw file(s) ({target}, ...); "
                                   "refused, an FCLib file is read alone")
        return obj

    def _read(self, name: str, obj: Any, length: int | None) -> np.ndarray:
        """The first ``length`` entries of the 1-D dataset ``obj`` (all of a scalar one for
        None), once its declared size and chunk size are within :data:`MAX_DATASET_BYTES`."""
        itemsize = obj.dtype.itemsize
        declared = int(np.prod(obj.shape, dtype=np.float64)) * itemsize
        chunk = int(np.prod(obj.chunks, dtype=np.float64)) * itemsize if obj.chunks else 0
        if max(declared, chunk) > MAX_DATASET_BYTES:
            what = (f"declares {declared} bytes (shape {obj.shape})" if declared > chunk else
                    f"is stored in chunks of {chunk} bytes (chunks {obj.chunks})")
            raise self.error(name, f"{what}; datasets and chunks above {MAX_DATASET_BYTES} "
                                   "bytes are refused before reading")
        try:
            return np.asarray(obj[()] if length is None else obj[:length])
        except (OSError, TypeError, ValueError) as exc:
            raise self.error(name, f"cannot be read ({exc})") from None

    def integer(self, name: str) -> int:
        obj = self.stored(name)
        if obj.dtype.kind not in "iu" or obj.shape is None or obj.size != 1 \
                or len(obj.shape) > 1:
            raise self.error(name, f"must hold one integer, got dtype {obj.dtype} and shape "
                                   f"{obj.shape}")
        return int(self._read(name, obj, None).reshape(-1)[0])

    def vector(self, name: str, kinds: str, length: int, exact: bool) -> np.ndarray:
        """The first ``length`` entries of a 1-D dataset whose type is of ``kinds`` and whose
        declared size fits ``length`` (equals it when ``exact``, else at least)."""
        obj = self.stored(name)
        described = "integers" if kinds == "iu" else "numbers"
        if obj.dtype.kind not in kinds or obj.shape is None or len(obj.shape) != 1:
            raise self.error(name, f"must be a vector of {described}, got dtype {obj.dtype} "
                                   f"and shape {obj.shape}")
        size = obj.shape[0]
        if size < length or (exact and size != length):
            raise self.error(name, f"has {size} entries, "
                                   f"{'expected' if exact else 'needs at least'} {length}")
        return self._read(name, obj, length)

    def indices(self, name: str, length: int, bound: int) -> np.ndarray:
        data = self.vector(name, "iu", length, exact=False).astype(np.int64)
        if length and (data.min() < 0 or data.max() >= bound):
            raise self.error(name, f"indices must lie in [0, {bound}), found "
                                   f"{data.min()}..{data.max()}")
        return data

    def floats(self, name: str, length: int, *, exact: bool = True) -> np.ndarray:
        data = self.vector(name, "fiu", length, exact).astype(float)
        if not np.all(np.isfinite(data)):
            raise self.error(name, f"holds {int(np.sum(~np.isfinite(data)))} non-finite "
                                   "number(s) (NaN or infinity)")
        return data
