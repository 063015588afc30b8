"""Fitting the stylizer and the style judge from content-paired styled takes."""
