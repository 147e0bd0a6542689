"""Drake (`engine.py`): its normal model and its friction, one module each."""
