"""Small text helpers shared by the command line and batch runner."""


def one_line(text):
    """Collapse ``text`` to one line: its non-empty lines, stripped, joined by ``"; "``.

    Parameters
    ----------
    text : str

    Returns
    -------
    str
    """
    return "; ".join(s.strip() for s in str(text).splitlines() if s.strip())
