"""Mismatch discovery: where recordings and the model disagree, which left-out physics explains it, and the proof."""
