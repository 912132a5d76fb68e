"""Recording and playback: MCAP files written from the daemon's published messages, replay
onto topics, export to ROS 2 formats. Depends on the daemon's topics, never the reverse.
"""
