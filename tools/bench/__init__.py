"""``gesturecast bench <what>``: benchmarks that print JSON, and the serve client they drive."""
