"""The canvas of the paper's figures: what lfd_segmentation/scripts/plot_segmentation.py draws and
test/integration/plot_figures.py checks (a layout that crops or resizes the canvas fails there)."""

DPI = 100
# Figure sizes in inches (x DPI = the PNG's pixels).
SIZES = {
    "skill_map": (12, 7),
    "correlation_best": (7, 6),
    "correlation_all": (12, 10),
    "relevance": (13, 6),
    "clasp_profile": (12, 7),
    "segmentation": (12, 8),
    "success_rates": (10, 5.5),
}


def size_px(kind):
    """(width, height) in pixels of a figure's PNG."""
    w, h = SIZES[kind]
    return int(round(w * DPI)), int(round(h * DPI))
