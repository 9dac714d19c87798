"""``hexdem paper``: the whole paper in one command, published numbers beside computed ones."""
