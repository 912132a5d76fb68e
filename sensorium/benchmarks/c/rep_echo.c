/* A do-nothing libzmq REP server that echoes every message (the C floor's server), or with
 * `router` a ROUTER that sends every message back whole (its routing-id frame first): the socket
 * pattern a server of several clients needs, at the same cost of C. Binds tcp://127.0.0.1 on a free
 * port (or the ENDPOINT given), prints "ready ENDPOINT", quits after 10 s without a message.
 * Usage: rep_echo [ENDPOINT [rep|router]] */
#include <stdio.h>
#include <string.h>
#include <zmq.h>

int main(int argc, char **argv) {
  const char *endpoint = argc > 1 ? argv[1] : "tcp://127.0.0.1:*";
  void *ctx = zmq_ctx_new();
  const int router = argc > 2 && strcmp(argv[2], "router") == 0;
  void *sock = zmq_socket(ctx, router ? ZMQ_ROUTER : ZMQ_REP);
  int timeout = 10000, linger = 0;
  zmq_setsockopt(sock, ZMQ_RCVTIMEO, &timeout, sizeof timeout);
  zmq_setsockopt(sock, ZMQ_LINGER, &linger, sizeof linger);
  if (zmq_bind(sock, endpoint) != 0) {
    fprintf(stderr, "rep_echo: cannot bind %s: %s\n", endpoint, zmq_strerror(zmq_errno()));
    return 1;
  }
  char bound[256];
  size_t len = sizeof bound;
  zmq_getsockopt(sock, ZMQ_LAST_ENDPOINT, bound, &len);
  printf("ready %s\n", bound);
  fflush(stdout);
  char buf[4096];
  for (;;) {
    int n = zmq_recv(sock, buf, sizeof buf, 0);
    if (n < 0)
      break; /* idle for 10 s: the parent is gone */
    int more = 0;
    size_t more_size = sizeof more;
    if (router) /* a frame of the message, then the next: all go back in order */
      zmq_getsockopt(sock, ZMQ_RCVMORE, &more, &more_size);
    if (zmq_send(sock, buf, (size_t)(n < (int)sizeof buf ? n : (int)sizeof buf), more ? ZMQ_SNDMORE : 0) < 0)
      break;
  }
  zmq_close(sock);
  zmq_ctx_term(ctx);
  return 0;
}
