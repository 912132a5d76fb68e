/* The raw floor of controller.c: a libzmq REQ socket doing step-sized ping-pongs with a
 * do-nothing REP server, or with `dealer` a DEALER doing them with rep_echo's ROUTER.
 * Usage: raw_req ENDPOINT STEPS [req|dealer] */
#include "timing.h" /* first: it sets _POSIX_C_SOURCE */
#include <string.h>
#include <zmq.h>


/* the bytes of a msgpack step request, as transport_roles.py's REQ floor sends */
static const char MSG[] = "\x83\xa2id\x01\xa7service\xaa/c0/robot/step\xa4" "args\x81\xa8" "duration\x08";
static void *sock;

static int ping(void *arg) {
  char buf[256];
  (void)arg;
  if (zmq_send(sock, MSG, sizeof MSG - 1, 0) < 0)
    return 1;
  return zmq_recv(sock, buf, sizeof buf, 0) < 0;
}

int main(int argc, char **argv) {
  if (argc != 3 && argc != 4) {
    fprintf(stderr, "usage: raw_req ENDPOINT STEPS [req|dealer]\n");
    return 2;
  }
  void *ctx = zmq_ctx_new();
  sock = zmq_socket(ctx, argc == 4 && strcmp(argv[3], "dealer") == 0 ? ZMQ_DEALER : ZMQ_REQ);
  int linger = 0;
  zmq_setsockopt(sock, ZMQ_LINGER, &linger, sizeof linger);
  if (zmq_connect(sock, argv[1]) != 0) {
    fprintf(stderr, "raw_req: cannot connect to %s: %s\n", argv[1], zmq_strerror(zmq_errno()));
    return 1;
  }
  for (int i = 0; i < 50; i++)
    if (ping(NULL) != 0)
      return 1;
  int rc = bench_run(atol(argv[2]), ping, NULL);
  zmq_close(sock);
  zmq_ctx_term(ctx);
  return rc;
}
