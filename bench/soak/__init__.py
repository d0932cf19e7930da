"""The real-process soak (``python -m bench soak``): its load, the station under it, and its report."""
