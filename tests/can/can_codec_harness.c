/* SPDX-License-Identifier: MIT */
/* A line protocol around the C CAN codec, so that tests/python/test_can_dbc.py can compare it with the DBC
 * (through cantools) bit for bit. One request per line on stdin, one answer per line on stdout:
 *   pack <msg> <node> <raw fields...>   -> "ok <id> <dlc> <hex>" | "einval"
 *   unpack <msg> <id> <dlc> <hex>       -> "ok <raw fields...>" | "rx <pour_can_rx_t>"
 * msg: sensors (seq_low encoder scale_rotating scale_target), torque (seq torque action mode limits),
 * heartbeat (mode faults rx_dropped overruns counter refused held), estop (assert), identity (hash tau_max fw init),
 * param_read (id), param_value and param_write (id value), param_ack (request id result), tare (scales),
 * experiment_start (kind),
 * clear_errors, stop, reset, param_save, zero and calibration_read (no fields).
 *   param <id>                          -> "ok <name> <unit or -> <min> <max>" | "none" (pour/params.h's table)
 * A line it cannot parse gets "error <reason>"; the harness never exits on bad input before EOF. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pour/can_codec.h"
#include "pour/params.h"

#define MAX_FIELDS 8

static int parse_longs(char *rest, long *v, int max) {
  int n = 0;
  for (char *tok = strtok(rest, " \t\r\n"); tok != NULL; tok = strtok(NULL, " \t\r\n")) {
    if (n == max) {
      return -1;
    }
    char *end = NULL;
    v[n++] = strtol(tok, &end, 0);
    if (end == tok || *end != '\0') {
      return -1;
    }
  }
  return n;
}

static void print_frame(pour_status_t st, const pour_can_frame_t *f) {
  if (st != POUR_OK) {
    puts("einval");
    return;
  }
  printf("ok %u %u ", (unsigned)f->id, (unsigned)f->dlc);
  for (unsigned i = 0; i < f->dlc; ++i) {
    printf("%02x", f->data[i]);
  }
  if (f->dlc == 0u) {
    printf("-");
  }
  putchar('\n');
}

/* The cmd of a message without signals, 0 for any other name. */
static uint8_t command_of(const char *msg) {
  if (strcmp(msg, "clear_errors") == 0) {
    return POUR_CAN_CMD_CLEAR_ERRORS;
  }
  if (strcmp(msg, "stop") == 0) {
    return POUR_CAN_CMD_STOP;
  }
  if (strcmp(msg, "calibration_start") == 0) {
    return POUR_CAN_CMD_CALIBRATION_START;
  }
  if (strcmp(msg, "param_save") == 0) {
    return POUR_CAN_CMD_PARAM_SAVE;
  }
  if (strcmp(msg, "zero") == 0) {
    return POUR_CAN_CMD_ZERO;
  }
  if (strcmp(msg, "calibration_read") == 0) {
    return POUR_CAN_CMD_CALIBRATION_READ;
  }
  return strcmp(msg, "reset") == 0 ? POUR_CAN_CMD_RESET : 0u;
}

/* ParamValue and ParamWrite share one layout. */
static uint8_t param_cmd_of(const char *msg) {
  if (strcmp(msg, "param_value") == 0) {
    return POUR_CAN_CMD_PARAM_VALUE;
  }
  return strcmp(msg, "param_write") == 0 ? POUR_CAN_CMD_PARAM_WRITE : 0u;
}

static void do_pack(const char *msg, long *v, int n) {
  pour_can_frame_t f;
  memset(&f, 0, sizeof f);
  if (n < 1 || v[0] < 0 || v[0] > 255) {
    puts("error node");
    return;
  }
  uint8_t node = (uint8_t)v[0];
  if (strcmp(msg, "sensors") == 0 && n == 5) {
    pour_can_sensors_t m = {(uint8_t)v[1], (uint32_t)v[2], (int16_t)v[3], (int16_t)v[4]};
    print_frame(pour_can_pack_sensors(node, &m, &f), &f);
  } else if (strcmp(msg, "torque") == 0 && n == 6) {
    pour_can_torque_t m = {(uint16_t)v[1], (q15_t)v[2], (uint8_t)v[3], (uint8_t)v[4], (uint8_t)v[5]};
    print_frame(pour_can_pack_torque(node, &m, &f), &f);
  } else if (strcmp(msg, "heartbeat") == 0 && n == 8) {
    pour_can_heartbeat_t m = {(uint8_t)v[1], (uint16_t)v[2], (uint16_t)v[3], (uint16_t)v[4], (uint8_t)v[5],
                              (uint8_t)v[6], (uint8_t)v[7]};
    print_frame(pour_can_pack_heartbeat(node, &m, &f), &f);
  } else if (strcmp(msg, "estop") == 0 && n == 2) {
    pour_can_estop_t m = {(uint8_t)v[1]};
    print_frame(pour_can_pack_estop(node, &m, &f), &f);
  } else if (strcmp(msg, "identity") == 0 && n == 5) {
    pour_can_identity_t m = {(uint32_t)v[1], (uint16_t)v[2], (uint8_t)v[3], (int8_t)v[4]};
    print_frame(pour_can_pack_identity(node, &m, &f), &f);
  } else if (strcmp(msg, "calibration_result") == 0 && n == 8) {
    pour_can_calibration_result_t m = {(uint8_t)v[1], (uint8_t)v[2], (uint8_t)v[3], (uint8_t)v[4],
                                       (uint16_t)v[5], (uint16_t)v[6], (uint8_t)v[7]};
    print_frame(pour_can_pack_calibration_result(node, &m, &f), &f);
  } else if (strcmp(msg, "drive_telemetry") == 0 && n == 6) {
    pour_can_drive_telemetry_t m = {(int16_t)v[1], (int16_t)v[2], (uint16_t)v[3], (uint16_t)v[4], (uint8_t)v[5]};
    print_frame(pour_can_pack_drive_telemetry(node, &m, &f), &f);
  } else if (strcmp(msg, "param_read") == 0 && n == 2) {
    pour_can_param_read_t m = {(uint8_t)v[1]};
    print_frame(pour_can_pack_param_read(node, &m, &f), &f);
  } else if (param_cmd_of(msg) != 0u && n == 3) {
    pour_can_param_t m = {(uint8_t)v[1], (int32_t)v[2]};
    print_frame(pour_can_pack_param(node, param_cmd_of(msg), &m, &f), &f);
  } else if (strcmp(msg, "param_ack") == 0 && n == 4) {
    pour_can_param_ack_t m = {(uint8_t)v[1], (uint8_t)v[2], (uint8_t)v[3]};
    print_frame(pour_can_pack_param_ack(node, &m, &f), &f);
  } else if (strcmp(msg, "experiment_start") == 0 && n == 2) {
    pour_can_experiment_start_t m = {(uint8_t)v[1]};
    print_frame(pour_can_pack_experiment_start(node, &m, &f), &f);
  } else if (strcmp(msg, "tare") == 0 && n == 2) {
    pour_can_tare_t m = {(uint8_t)v[1]};
    print_frame(pour_can_pack_tare(node, &m, &f), &f);
  } else if (command_of(msg) != 0u && n == 1) {
    print_frame(pour_can_pack_command(node, command_of(msg), &f), &f);
  } else {
    puts("error message or field count");
  }
}

static int parse_hex(const char *hex, uint8_t *data, unsigned dlc) {
  if (strcmp(hex, "-") == 0) {
    return dlc == 0u ? 0 : -1;
  }
  if (strlen(hex) != 2u * dlc) {
    return -1;
  }
  for (unsigned i = 0; i < dlc; ++i) {
    char byte[3] = {hex[2 * i], hex[2 * i + 1], '\0'};
    char *end = NULL;
    data[i] = (uint8_t)strtoul(byte, &end, 16);
    if (*end != '\0') {
      return -1;
    }
  }
  return 0;
}

static void do_unpack(const char *msg, char *rest) {
  char *id_s = strtok(rest, " \t\r\n");
  char *dlc_s = strtok(NULL, " \t\r\n");
  char *hex = strtok(NULL, " \t\r\n");
  if (id_s == NULL || dlc_s == NULL || hex == NULL) {
    puts("error unpack needs id dlc hex");
    return;
  }
  pour_can_frame_t f;
  memset(&f, 0, sizeof f);
  unsigned long id = strtoul(id_s, NULL, 0);
  unsigned long dlc = strtoul(dlc_s, NULL, 0);
  if (id > 0x7FFu || dlc > 8u || parse_hex(hex, f.data, (unsigned)dlc) != 0) {
    puts("error frame");
    return;
  }
  f.id = (uint16_t)id;
  f.dlc = (uint8_t)dlc;
  pour_can_rx_t rc;
  char out[128];
  if (strcmp(msg, "sensors") == 0) {
    pour_can_sensors_t m = {0};
    rc = pour_can_unpack_sensors(&f, &m);
    snprintf(out, sizeof out, "%u %lu %d %d", (unsigned)m.seq_low, (unsigned long)m.encoder, m.scale_rotating_g,
             m.scale_target_g);
  } else if (strcmp(msg, "torque") == 0) {
    pour_can_torque_t m = {0};
    rc = pour_can_unpack_torque(&f, &m);
    snprintf(out, sizeof out, "%u %d %u %u %u", (unsigned)m.seq, m.torque, (unsigned)m.action,
             (unsigned)m.mode, (unsigned)m.limits);
  } else if (strcmp(msg, "heartbeat") == 0) {
    pour_can_heartbeat_t m = {0};
    rc = pour_can_unpack_heartbeat(&f, &m);
    snprintf(out, sizeof out, "%u %u %u %u %u %u %u", (unsigned)m.mode, (unsigned)m.faults,
             (unsigned)m.rx_dropped, (unsigned)m.overruns, (unsigned)m.counter, (unsigned)m.refused,
             (unsigned)m.held);
  } else if (strcmp(msg, "estop") == 0) {
    pour_can_estop_t m = {0};
    rc = pour_can_unpack_estop(&f, &m);
    snprintf(out, sizeof out, "%u", (unsigned)m.assert_estop);
  } else if (strcmp(msg, "identity") == 0) {
    pour_can_identity_t m = {0};
    rc = pour_can_unpack_identity(&f, &m);
    snprintf(out, sizeof out, "%lu %u %u %d", (unsigned long)m.weights_hash, (unsigned)m.tau_max_cnm,
             (unsigned)m.fw_version, (int)m.init_status);
  } else if (strcmp(msg, "calibration_result") == 0) {
    pour_can_calibration_result_t m = {0};
    rc = pour_can_unpack_calibration_result(&f, &m);
    snprintf(out, sizeof out, "%u %u %u %u %u %u %u", (unsigned)m.status, (unsigned)m.stored,
             (unsigned)m.encoder_reversed, (unsigned)m.pole_pairs, (unsigned)m.resistance_mohm,
             (unsigned)m.inductance_uh, (unsigned)m.electrical_offset);
  } else if (strcmp(msg, "drive_telemetry") == 0) {
    pour_can_drive_telemetry_t m = {0};
    rc = pour_can_unpack_drive_telemetry(&f, &m);
    snprintf(out, sizeof out, "%d %d %u %u %u", m.id_2ma, m.iq_2ma, (unsigned)m.vbus_mv, (unsigned)m.drive_faults,
             (unsigned)m.crystal_4mhz);
  } else if (strcmp(msg, "param_read") == 0) {
    pour_can_param_read_t m = {0};
    rc = pour_can_unpack_param_read(&f, &m);
    snprintf(out, sizeof out, "%u", (unsigned)m.param_id);
  } else if (param_cmd_of(msg) != 0u) {
    pour_can_param_t m = {0, 0};
    rc = pour_can_unpack_param(&f, param_cmd_of(msg), &m);
    snprintf(out, sizeof out, "%u %ld", (unsigned)m.param_id, (long)m.value);
  } else if (strcmp(msg, "param_ack") == 0) {
    pour_can_param_ack_t m = {0, 0, 0};
    rc = pour_can_unpack_param_ack(&f, &m);
    snprintf(out, sizeof out, "%u %u %u", (unsigned)m.request, (unsigned)m.param_id, (unsigned)m.result);
  } else if (strcmp(msg, "experiment_start") == 0) {
    pour_can_experiment_start_t m = {0};
    rc = pour_can_unpack_experiment_start(&f, &m);
    snprintf(out, sizeof out, "%u", (unsigned)m.kind);
  } else if (strcmp(msg, "tare") == 0) {
    pour_can_tare_t m = {0};
    rc = pour_can_unpack_tare(&f, &m);
    snprintf(out, sizeof out, "%u", (unsigned)m.scales);
  } else if (command_of(msg) != 0u) {
    rc = pour_can_unpack_command(&f, command_of(msg));
    out[0] = '\0';
  } else {
    puts("error message");
    return;
  }
  if (rc == POUR_CAN_RX_OK) {
    printf("ok %s\n", out);
  } else {
    printf("rx %d\n", (int)rc);
  }
}

int main(void) {
  char line[512];
  while (fgets(line, sizeof line, stdin) != NULL) {
    char *verb = strtok(line, " \t\r\n");
    char *msg = strtok(NULL, " \t\r\n");
    char *rest = strtok(NULL, "");
    if (verb == NULL || msg == NULL) {
      puts("error need verb and message");
    } else if (strcmp(verb, "pack") == 0) {
      long v[MAX_FIELDS];
      int n = parse_longs(rest != NULL ? rest : (char[]){""}, v, MAX_FIELDS);
      if (n < 0) {
        puts("error fields");
      } else {
        do_pack(msg, v, n);
      }
    } else if (strcmp(verb, "param") == 0) {
      const long id = strtol(msg, NULL, 0);
      const pour_param_info_t *info = id >= 0 && id <= 255 ? pour_param_info((uint8_t)id) : NULL;
      if (info == NULL) {
        puts("none");
      } else {
        printf("ok %s %s %ld %ld\n", info->name, info->unit[0] != '\0' ? info->unit : "-", (long)info->min,
               (long)info->max);
      }
    } else if (strcmp(verb, "unpack") == 0 && rest != NULL) {
      do_unpack(msg, rest);
    } else {
      puts("error verb");
    }
    fflush(stdout);
  }
  return 0;
}
