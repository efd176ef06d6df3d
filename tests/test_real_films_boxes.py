"""``benchmarks/real_films.py`` draws the boxes the reviewers' kits drew (no film is read here).

The kits' boxes as they ran them: review16 ``runs/table.md`` (rounded sizes, clipped to the frame:
arzafiruddin's 120 % box loses its top rows), review18/19 ``runs/*/*/boxes.txt`` (each side rounded
at the end). A box one pixel off is another run than the kit's, so every variant is checked.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from _film_refs import FILMS, perturb  # noqa: E402

KIT_BOXES = {
    # review16 runs/table.md (shift+10, big120, small80)
    "juangomez_pendulum": {"shift+10": (501, 219, 61, 66), "s120": (489, 206, 73, 79), "s080": (501, 218, 49, 53)},
    "katie_pendulum": {"shift+10": (292, 212, 46, 73), "s120": (282, 198, 55, 88), "s080": (292, 212, 37, 58)},
    "necros_ball": {"shift+10": (67, 458, 44, 60), "s120": (58, 446, 53, 72), "s080": (68, 458, 35, 48)},
    "trflorian_ball4": {"shift+10": (851, 282, 110, 125), "s120": (829, 258, 132, 150), "s080": (851, 282, 88, 100)},
    "arzafiruddin_bounce": {"shift+10": (944, 19, 99, 101), "s120": (924, 0, 119, 120), "s080": (944, 19, 79, 81)},
    # review18 / review19 boxes.txt (shift, s120, s080)
    "adi_ball": {"shift+10": (437, 246, 53, 56), "s120": (427, 234, 64, 67), "s080": (437, 246, 42, 45)},
    "izhan_ball": {"shift+10": (280, 75, 84, 84), "s120": (264, 59, 101, 101), "s080": (280, 75, 67, 67)},
    "sborquez_video1": {"shift+10": (447, 580, 32, 24), "s120": (441, 576, 38, 29), "s080": (447, 580, 26, 19)},
    "chulminy_img": {"shift+10": (763, 435, 46, 48), "s120": (753, 425, 55, 58), "s080": (763, 435, 37, 38)},
    "kx_pendulum": {"shift+10": (586, 243, 132, 132), "s120": (560, 217, 158, 158), "s080": (586, 243, 106, 106)},
    "nouyang_bounce": {"shift+10": (84, 96, 395, 215), "s120": (6, 54, 474, 258), "s080": (84, 96, 316, 172)},
}
#: sborquez_video2's two bobs (review18 boxes.txt)
BOBS = {"shift+10": ((89, 250, 38, 38), (350, 250, 38, 38)), "s120": ((81, 242, 46, 46), (342, 242, 46, 46)),
        "s080": ((89, 250, 30, 30), (350, 250, 30, 30))}  # fmt: skip


def test_every_box_variant_is_the_kits():
    films = {f.name: f for f in FILMS}
    assert len(films) == len(FILMS) == 12
    for name, variants in KIT_BOXES.items():
        f = films[name]
        (box,) = f.boxes.values()
        assert perturb(box, "base", f.size, f.rounding) == box
        for kind, want in variants.items():
            assert perturb(box, kind, f.size, f.rounding) == want, (name, kind)
    f = films["sborquez_video2"]
    for kind, want in BOBS.items():
        assert tuple(perturb(b, kind, f.size, f.rounding) for b in f.boxes.values()) == want, kind
