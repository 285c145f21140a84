"""Figure files: which ones bioflex-jsb wrote, and where a figure may be written.

Near the base of the layers (it imports nothing of the project but errors and files;
matplotlib and PIL only when called): the sinks' figures, the section loads' and the
results' ``.plot()`` methods check their files here.
"""

from __future__ import annotations

from pathlib import Path

from bioflex_jsb.errors import InputError
from bioflex_jsb.files import open_input

# Largest file looked into as a possible figure of ours [bytes]: our PNGs are < 1 MB.
MAX_PLOT_FILE_BYTES = 64 * 1024 * 1024


def is_our_plot(path: str | Path) -> bool:
    """Whether ``path`` is a PNG that bioflex-jsb wrote (its Software tag starts with
    ``bioflex-jsb``); anything else, or an unreadable file, is not ours."""
    from PIL import Image

    try:
        with open_input(path, "plot file", MAX_PLOT_FILE_BYTES) as f, Image.open(f) as image:
            if image.format != "PNG":
                return False
            return str(image.info.get("Software", "")).startswith("bioflex-jsb")
    # not an image PIL can read (PIL.UnidentifiedImageError is an OSError); a header that
    # claims more pixels than PIL opens (DecompressionBombError); a broken chunk (PIL raises
    # SyntaxError or ValueError for some): none of them is a plot of ours
    # a FIFO, a device or a file larger than a figure of ours (InputError, a ValueError)
    except (OSError, ValueError, SyntaxError, Image.DecompressionBombError):
        return False


def figure_suffixes() -> list[str]:
    """The file suffixes (no dot) matplotlib writes."""
    from matplotlib.backend_bases import FigureCanvasBase

    return sorted(FigureCanvasBase.get_supported_filetypes())


def check_plot_target(path, force: bool = False) -> Path:
    """``path`` as a figure file the library may write (InputError, one line, otherwise):
    a non-empty name with a suffix matplotlib writes, in a directory that exists, not an
    existing file other than a plot of ours (:func:`is_our_plot`) unless ``force``. Without
    it the results' ``.plot(path)`` would replace a user's file, write ``x.png`` for ``x``
    and return ``x``, and write ``plots.png`` for a directory ``plots``."""
    if not isinstance(path, str | Path) or not str(path):
        raise InputError(f"a plot needs a file name ending in a figure suffix, got {path!r}")
    out = Path(path)
    formats = figure_suffixes()
    if out.suffix.lower().lstrip(".") not in formats:
        raise InputError(f"plot file {str(out)!r}: give a name ending in one of "
                         f"{', '.join('.' + s for s in formats)}")
    if out.exists() and (not out.is_file() or not (force or is_our_plot(out))):
        raise InputError(f"plot file {str(out)!r} exists and is not a plot bioflex-jsb "
                         "wrote; give another name or force=True to replace it")
    if not out.parent.is_dir():
        raise InputError(f"plot file {str(out)!r}: the directory {str(out.parent)!r} does not "
                         "exist")
    return out
