"""Program text for CNC controls: the shared program model and one module per dialect."""
