// Load each ontology file with the OWL API (the library inside Protege), report what its parser could not
// read and what the OWL 2 DL profile check finds, save it as Turtle and load the saved file again.
//
//   java -cp <owlapi jars> tests/java/RoundTrip.java CATALOG OUT_DIR FILE...
//
// CATALOG is ontologies/catalog-v001.xml: owl:imports resolve through it to the files beside it, and an
// import it does not map fails instead of being fetched. Each FILE is saved to OUT_DIR under its own name.
// One line per finding, for tests/test_owl_api.py to read:
//   file NAME axioms N saved-axioms M unparsed U violations V
//   unparsed NAME TRIPLE
//   violation NAME TEXT
// The exit status is 3 when any file has an unparsed triple or a profile violation (1 is Java's for an
// uncaught exception, 2 a wrong command line).

import java.io.File;
import java.util.HashMap;
import java.util.Map;
import java.util.stream.Collectors;
import javax.xml.parsers.DocumentBuilderFactory;
import org.semanticweb.owlapi.apibinding.OWLManager;
import org.semanticweb.owlapi.formats.TurtleDocumentFormat;
import org.semanticweb.owlapi.io.RDFParserMetaData;
import org.semanticweb.owlapi.io.RDFTriple;
import org.semanticweb.owlapi.model.IRI;
import org.semanticweb.owlapi.model.OWLDocumentFormat;
import org.semanticweb.owlapi.model.OWLOntology;
import org.semanticweb.owlapi.model.OWLOntologyIRIMapper;
import org.semanticweb.owlapi.model.OWLOntologyManager;
import org.semanticweb.owlapi.profiles.OWL2DLProfile;
import org.semanticweb.owlapi.profiles.OWLProfileViolation;
import org.w3c.dom.Element;
import org.w3c.dom.NodeList;

public class RoundTrip {
    public static void main(String[] args) throws Exception {
        if (args.length < 3) {
            System.err.println("usage: RoundTrip CATALOG OUT_DIR FILE...");
            System.exit(2);
        }
        File catalog = new File(args[0]);
        Map<IRI, IRI> mapped = readCatalog(catalog);
        File outDir = new File(args[1]);
        boolean clean = true;
        for (int i = 2; i < args.length; i++) {
            clean &= roundTrip(new File(args[i]), outDir, mapped);
        }
        System.exit(clean ? 0 : 3);
    }

    static Map<IRI, IRI> readCatalog(File catalog) throws Exception {
        Map<IRI, IRI> mapped = new HashMap<>();
        NodeList uris = DocumentBuilderFactory.newInstance().newDocumentBuilder().parse(catalog)
            .getElementsByTagName("uri");
        for (int i = 0; i < uris.getLength(); i++) {
            Element uri = (Element) uris.item(i);
            File file = new File(catalog.getParentFile(), uri.getAttribute("uri"));
            mapped.put(IRI.create(uri.getAttribute("name")), IRI.create(file.getAbsoluteFile().toURI()));
        }
        return mapped;
    }

    static OWLOntologyManager manager(Map<IRI, IRI> mapped) {
        OWLOntologyManager manager = OWLManager.createOWLOntologyManager();
        // An import the catalogue does not map goes to a file that is not there: nothing is fetched.
        OWLOntologyIRIMapper mapper = iri -> mapped.getOrDefault(
            iri, IRI.create(new File("/nonexistent/unmapped-import").toURI()));
        manager.getIRIMappers().set(mapper);
        return manager;
    }

    static boolean roundTrip(File file, File outDir, Map<IRI, IRI> mapped) throws Exception {
        String name = file.getName();
        OWLOntologyManager manager = manager(mapped);
        OWLOntology ontology = manager.loadOntologyFromOntologyDocument(file);
        OWLDocumentFormat format = manager.getOntologyFormat(ontology);
        long unparsed = 0;
        if (format != null && format.getOntologyLoaderMetaData().isPresent()) {
            RDFParserMetaData meta = (RDFParserMetaData) format.getOntologyLoaderMetaData().get();
            for (RDFTriple triple : meta.getUnparsedTriples().collect(Collectors.toList())) {
                System.out.println("unparsed " + name + " " + triple);
                unparsed++;
            }
        }
        long violations = 0;
        for (OWLProfileViolation violation : new OWL2DLProfile().checkOntology(ontology).getViolations()) {
            System.out.println("violation " + name + " " + violation.toString().replace('\n', ' '));
            violations++;
        }
        TurtleDocumentFormat turtle = new TurtleDocumentFormat();
        if (format != null && format.isPrefixOWLDocumentFormat()) {
            turtle.copyPrefixesFrom(format.asPrefixOWLDocumentFormat());
        }
        File saved = new File(outDir, name);
        manager.saveOntology(ontology, turtle, IRI.create(saved.getAbsoluteFile().toURI()));
        OWLOntology reloaded = manager(mapped).loadOntologyFromOntologyDocument(saved);
        System.out.println("file " + name + " axioms " + ontology.getAxiomCount() + " saved-axioms "
            + reloaded.getAxiomCount() + " unparsed " + unparsed + " violations " + violations);
        return unparsed == 0 && violations == 0;
    }
}
