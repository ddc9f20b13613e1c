"""The farm's progress (issue 49): a k/N counter with an ETA, in place on a terminal, one line per
finished item elsewhere (as `atrous denoise --sequence` counts its frames)."""
import io

from atrous.farm.progress import Progress


def test_one_line_per_finished_item_when_not_a_terminal():
    out = io.StringIO()
    p = Progress(3, 0, stream=out)
    p.update(0, 0, 2)
    p.update(1, 0, 2)
    p.update(1, 0, 1)  # nothing finished: no line
    p.update(2, 1, 0)
    p.update(2, 1, 0, final=True)
    lines = out.getvalue().splitlines()
    assert [ln.split(",")[0] for ln in lines] == ["1/3 done", "2/3 done", "2/3 done"]
    assert all("ETA" in ln and "[" not in ln for ln in lines)


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_redrawn_in_place_on_a_terminal():
    out = _Tty()
    p = Progress(2, 0, stream=out)
    p.update(1, 0, 1, final=False)
    p.update(2, 0, 0, final=True)
    text = out.getvalue()
    assert text.startswith("\r\x1b[2K[") and "2/2 done" in text and text.endswith("\n")
