"""Objective evaluation: gesture metrics, beat consistency, speech following, the frozen FGD encoder
and style classifier, held-out denoising.
"""
