"""Point-list program text for CNC controls: the program model, the moves, one module per dialect, the writer table."""
