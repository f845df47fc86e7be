// Foxglove's protobuf definitions as @foxglove/schemas generates them, for
// the tests that read what the recorder writes (the MCAP check, the
// Foxglove client): a protobufjs Root of every Foxglove message type. Each
// caller passes its own protobufjs and @foxglove/schemas/internal, from its
// own node_modules.
export function foxgloveProtobuf(protobuf, schemasInternal) {
  const { foxgloveMessageSchemas, foxgloveEnumSchemas, generateProto } = schemasInternal;
  const root = new protobuf.Root();
  for (const file of ["google/protobuf/timestamp.proto", "google/protobuf/duration.proto"])
    root.addJSON(protobuf.common.get(file).nested);
  const enums = Object.values(foxgloveEnumSchemas ?? {});
  for (const [name, schema] of Object.entries(foxgloveMessageSchemas))
    protobuf.parse(generateProto(schema, enums.filter((e) => e.parentSchemaName === name)), root,
                   { keepCase: true });
  root.resolveAll();
  return root;
}
